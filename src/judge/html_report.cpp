#include "judge/html_report.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>

#include <fmt/format.h>

#include "image/image_io.hpp"
#include "judge/false_colour.hpp"
#include "judge/image_compare.hpp"
#include "judge/svg_plot.hpp"

namespace pathlab {
namespace fs = std::filesystem;
namespace {

constexpr int kMaxDisplayWidth = 512;

// A file-name-safe form of an algorithm name.
std::string slug(const std::string& name) {
    std::string out;
    for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    return out;
}

// A relative path as a URL path: every byte but the unreserved characters (RFC 3986) and '/'
// percent-encoded, so that '#', '?', '%', spaces and quotes in file names neither break links
// nor reach the page as markup.
std::string url_path(const std::string& path) {
    std::string out;
    for (const char c : path) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (std::isalnum(u) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
            out += c;
        } else {
            out += fmt::format("%{:02X}", unsigned(u));
        }
    }
    return out;
}

std::string exposure_tag(int stops) { return stops == 0 ? "0" : fmt::format("{}{}", stops > 0 ? 'p' : 'm', std::abs(stops)); }

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
    return buf;
}

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 16px 24px; background: #f7f7f7; color: #222; }
h1 { font-size: 22px; margin-bottom: 4px; } h2 { font-size: 18px; margin-top: 28px; }
.meta { color: #555; font-size: 13px; } .note { background: #fff3cd; border: 1px solid #e0c36c; padding: 6px 10px; }
.controls { position: sticky; top: 0; z-index: 2; background: #f7f7f7; padding: 8px 0; border-bottom: 1px solid #ddd; font-size: 14px; }
.controls input, .controls select { vertical-align: middle; }
.grid { display: flex; flex-wrap: wrap; gap: 12px; }
figure { margin: 0; background: #fff; padding: 6px; border: 1px solid #ddd; }
figcaption { font-size: 13px; margin-top: 4px; line-height: 1.4; }
.view { position: relative; overflow: hidden; cursor: zoom-in; background: #000; }
.view.zoomed { cursor: zoom-out; }
.view .layer { position: absolute; left: 0; top: 0; transform-origin: 0 0; }
.view img { position: absolute; left: 0; top: 0; image-rendering: pixelated; }
.view .crop { position: absolute; border-style: solid; border-color: #ffd400; box-sizing: border-box; pointer-events: none; }
.inset img { image-rendering: pixelated; display: block; }
.plots { display: flex; flex-wrap: wrap; gap: 12px; }
.bar { display: flex; align-items: center; gap: 6px; font-size: 13px; margin: 8px 0; }
.bar img { height: 14px; width: 256px; image-rendering: pixelated; }
table { border-collapse: collapse; background: #fff; font-size: 14px; }
th, td { border: 1px solid #ccc; padding: 4px 10px; text-align: right; } th:first-child, td:first-child { text-align: left; }
td.best { font-weight: bold; }
)";

// Toggles exposure (swaps the PNG of every image) and a synchronised pixel-level zoom.
constexpr const char* kScript = R"(
(function () {
  'use strict';
  const slider = document.getElementById('exposure');
  const exposureText = document.getElementById('exposure-value');
  const zoomSelect = document.getElementById('zoom');
  const pixelText = document.getElementById('pixel');
  const views = Array.from(document.querySelectorAll('.view'));
  let focus = null;  // the zoomed pixel {x, y}, or null
  function tag(v) { return v === 0 ? '0' : (v > 0 ? 'p' : 'm') + Math.abs(v); }
  function setExposure() {
    const v = Number(slider.value);
    exposureText.textContent = (v > 0 ? '+' : '') + v;
    document.querySelectorAll('img[data-stem]').forEach(function (img) {
      img.src = img.dataset.stem + '_e' + tag(v) + '.png';
    });
  }
  function layout() {
    views.forEach(function (view) {
      const layer = view.querySelector('.layer');
      const w = Number(view.dataset.w), h = Number(view.dataset.h);
      const dw = view.clientWidth, dh = view.clientHeight, base = dw / w;
      let s = base, tx = 0, ty = 0;
      if (focus) {
        s = base * Number(zoomSelect.value);
        tx = Math.min(0, Math.max(dw - w * s, dw / 2 - (focus.x + 0.5) * s));
        ty = Math.min(0, Math.max(dh - h * s, dh / 2 - (focus.y + 0.5) * s));
      }
      layer.style.transform = 'translate(' + tx + 'px, ' + ty + 'px) scale(' + s + ')';
      view.classList.toggle('zoomed', focus !== null);
    });
    pixelText.textContent = focus ? 'zoomed at pixel (' + focus.x + ', ' + focus.y + ')' : '';
  }
  views.forEach(function (view) {
    view.addEventListener('click', function (e) {
      if (focus) { focus = null; } else {
        const r = view.getBoundingClientRect(), w = Number(view.dataset.w), h = Number(view.dataset.h);
        const base = view.clientWidth / w;
        focus = { x: Math.min(w - 1, Math.max(0, Math.floor((e.clientX - r.left) / base))),
                  y: Math.min(h - 1, Math.max(0, Math.floor((e.clientY - r.top) / base))) };
      }
      layout();
    });
  });
  slider.addEventListener('input', setExposure);
  zoomSelect.addEventListener('change', layout);
  document.addEventListener('keydown', function (e) { if (e.key === 'Escape') { focus = null; layout(); } });
  // A link may open the page at a given state: report.html#exposure=2&zoom=16&pixel=40,25
  const state = new URLSearchParams(window.location.hash.slice(1));
  if (state.has('exposure')) slider.value = state.get('exposure');
  if (state.has('zoom')) zoomSelect.value = state.get('zoom');
  const px = (state.get('pixel') || '').split(',').map(Number);
  if (px.length === 2 && px.every(Number.isInteger)) focus = { x: px[0], y: px[1] };
  setExposure();
  layout();
  document.body.dataset.ready = 'yes';  // for the browser test: the script ran to its end
})();
)";

struct Figure {
    std::string stem;  // relative to the HTML, without "_e<tag>.png"; empty for a fixed image
    std::string src;   // fixed image
    std::string alt, caption;
};

// An image at most kMaxDisplayWidth wide, zoomable; `crops` are outlined on it.
std::string figure_html(const Figure& f, int w, int h, const std::vector<PixelRect>& crops = {}) {
    const int dw = std::min(w, kMaxDisplayWidth);
    const int dh = int(std::lround(double(h) * dw / w));
    const std::string img = f.stem.empty()
                                ? fmt::format("<img src=\"{}\" width=\"{}\" height=\"{}\" alt=\"{}\">", xml_escape(f.src), w, h, xml_escape(f.alt))
                                : fmt::format("<img data-stem=\"{0}\" src=\"{0}_e0.png\" width=\"{1}\" height=\"{2}\" alt=\"{3}\">",
                                              xml_escape(f.stem), w, h, xml_escape(f.alt));
    // Outlines about 2 display pixels wide (the layer is scaled by dw / w).
    const double border = 2.0 * double(w) / double(dw);
    std::string boxes;
    for (const PixelRect& c : crops)
        boxes += fmt::format("<div class=\"crop\" style=\"left:{}px;top:{}px;width:{}px;height:{}px;border-width:{:.2f}px\"></div>", c.x, c.y,
                             c.width, c.height, border);
    return fmt::format("<figure style=\"width:{}px\"><div class=\"view\" style=\"width:{}px;height:{}px\" data-w=\"{}\" data-h=\"{}\">"
                       "<div class=\"layer\" style=\"width:{}px;height:{}px\">{}{}</div></div><figcaption>{}</figcaption></figure>\n",
                       dw, dw, dh, w, h, w, h, img, boxes, f.caption);
}

// A magnified inset (no zoom): the crop shown about 192 pixels wide, pixelated.
std::string inset_html(const std::string& stem, const PixelRect& c, const std::string& caption) {
    const int scale = std::max(1, 192 / c.width);
    return fmt::format("<figure class=\"inset\"><img data-stem=\"{0}\" src=\"{0}_e0.png\" width=\"{1}\" height=\"{2}\" alt=\"inset\">"
                       "<figcaption>{3}</figcaption></figure>\n",
                       xml_escape(stem), c.width * scale, c.height * scale, caption);
}

// Per pixel, the standard error over the reference (each the mean of its three channels): how
// far from converged each part of the image is, in proportion to its brightness. Pixels whose
// reference is not above `darkest` are left at 0 (their relative error says little); `median`
// and `p90` get the 50th and 90th percentiles over the others.
Image relative_error(const Image& se, const Image& reference, double darkest, double& median, double& p90) {
    Image out(se.width(), se.height());
    std::vector<double> values;
    for (size_t p = 0; p < se.pixel_count(); ++p) {
        const double ref = (reference[p][0] + reference[p][1] + reference[p][2]) / 3.0, s = (se[p][0] + se[p][1] + se[p][2]) / 3.0;
        if (!(ref > darkest) || !std::isfinite(s)) continue;
        const float r = float(s / ref);
        out[p] = Rgb(r, r, r);
        values.push_back(r);
    }
    median = p90 = 0;
    if (!values.empty()) {
        std::sort(values.begin(), values.end());
        median = values[values.size() / 2];
        p90 = values[std::min(values.size() - 1, values.size() * 9 / 10)];
    }
    return out;
}

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

}  // namespace

std::string report_files_dir(const std::string& html_path) {
    const fs::path p(html_path);
    return (p.parent_path() / (p.stem().string() + "_files")).string();
}

std::vector<std::string> write_html_report(const ReportData& data, const std::string& html_path) {
    const fs::path files_dir = report_files_dir(html_path);
    // Links to the images: relative, percent-encoded (and, in attributes, HTML-escaped).
    const std::string files_rel = url_path(files_dir.filename().string());
    const int w = data.reference.width(), h = data.reference.height();
    for (const PixelRect& c : data.crops) crop(data.reference, c);  // throws std::invalid_argument if outside
    std::vector<std::string> written{html_path};
    const auto write_png = [&](const Image8& img, const std::string& name) {
        write_png8(img, (files_dir / name).string());
        written.push_back((files_dir / name).string());
        return files_rel + "/" + url_path(name);
    };
    const auto write_text = [&](const std::string& text, const std::string& name) {
        write_text_file((files_dir / name).string(), text);
        written.push_back((files_dir / name).string());
        return files_rel + "/" + url_path(name);
    };
    // Every tone-mapped image at every exposure; returns the stem for data-stem.
    const auto write_exposures = [&](const Image& img, const std::string& name) {
        for (int e = kReportMinExposure; e <= kReportMaxExposure; ++e)
            write_png(to_srgb8(img, float(e)), fmt::format("{}_e{}.png", name, exposure_tag(e)));
        return files_rel + "/" + url_path(name);
    };

    // Statistics, and the error images on one shared scale: the largest of the renders'
    // 99th percentiles of |difference| (so the noisiest render just saturates); the same for
    // the standard errors.
    std::vector<ImageDifference> diffs;
    std::vector<double> rmses, efficiencies;
    double scale = 0, se_scale = 0;
    for (const ReportRender& r : data.renders) {
        diffs.push_back(compare_images(r.mean, data.reference));
        rmses.push_back(rmse_against_reference(r.mean, data.reference, data.reference_se));
        // Efficiency: the inverse of the work needed for a given error, 1 / (MSE x time).
        const double mse_seconds = rmses.back() * rmses.back() * r.stats.seconds;
        efficiencies.push_back(mse_seconds > 0 ? 1.0 / mse_seconds : 0.0);
        scale = std::max(scale, difference_scale(r.mean, data.reference));
        if (r.std_error.pixel_count() == r.mean.pixel_count() && r.mean.pixel_count() > 0)
            se_scale = std::max(se_scale, magnitude_scale(r.std_error));
    }
    if (!(scale > 0)) scale = 1;
    if (!(se_scale > 0)) se_scale = 1;
    const size_t best = rmses.empty() ? 0 : size_t(std::min_element(rmses.begin(), rmses.end()) - rmses.begin());
    const size_t most_efficient =
        efficiencies.empty() ? 0 : size_t(std::max_element(efficiencies.begin(), efficiencies.end()) - efficiencies.begin());

    // The relative errors, on one scale: the largest of the renders' 90th percentiles; pixels
    // darker than 1% of the reference's mean left out.
    double reference_mean = 0;
    for (size_t p = 0; p < data.reference.pixel_count(); ++p)
        reference_mean += (data.reference[p][0] + data.reference[p][1] + data.reference[p][2]) / 3.0;
    reference_mean /= double(std::max<size_t>(1, data.reference.pixel_count()));
    std::vector<Image> relative(data.renders.size());
    std::vector<std::pair<double, double>> relative_percentiles(data.renders.size());
    double relative_scale = 0;
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        if (r.std_error.pixel_count() != r.mean.pixel_count() || r.mean.pixel_count() != data.reference.pixel_count()) continue;
        auto& [median, p90] = relative_percentiles[i];
        relative[i] = relative_error(r.std_error, data.reference, 0.01 * reference_mean, median, p90);
        relative_scale = std::max(relative_scale, p90);
    }
    if (!(relative_scale > 0)) relative_scale = 1;

    std::string images, errors, std_errors, relative_errors, insets;
    images += figure_html({write_exposures(data.reference, "reference"), "", "reference",
                           "<b>reference</b><br>" + xml_escape(data.reference_label)},
                          w, h, data.crops);
    std::vector<std::string> inset_rows(data.crops.size());
    for (size_t k = 0; k < data.crops.size(); ++k)
        inset_rows[k] += inset_html(write_exposures(crop(data.reference, data.crops[k]), fmt::format("reference_crop{}", k)), data.crops[k],
                                    "<b>reference</b>");
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        const std::string name = slug(r.algorithm);
        const std::string caption = fmt::format("<b>{}</b><br>{} spp, {:.2f} s{}<br>RMSE {:.4g}", xml_escape(r.algorithm), r.stats.spp,
                                                r.stats.seconds, r.stats.interrupted ? " (interrupted)" : "", rmses[i]);
        images += figure_html({write_exposures(r.mean, name), "", r.algorithm, caption}, w, h, data.crops);
        errors += figure_html({"", write_png(false_colour_difference(r.mean, data.reference, scale), name + "_error.png"),
                               r.algorithm + " error", fmt::format("<b>{}</b> − reference", xml_escape(r.algorithm))},
                              w, h);
        if (r.std_error.pixel_count() == r.mean.pixel_count() && r.mean.pixel_count() > 0)
            std_errors += figure_html({"", write_png(false_colour_magnitude(r.std_error, se_scale), name + "_stderr.png"),
                                       r.algorithm + " standard error",
                                       fmt::format("<b>{}</b><br>mean standard error {:.3g}", xml_escape(r.algorithm),
                                                   [&] {
                                                       double sum = 0;
                                                       size_t n = 0;
                                                       for (size_t p = 0; p < r.std_error.pixel_count(); ++p)
                                                           for (int c = 0; c < 3; ++c)
                                                               if (std::isfinite(r.std_error[p][c])) sum += r.std_error[p][c], ++n;
                                                       return n ? sum / double(n) : 0.0;
                                                   }())},
                                      w, h);
        if (relative[i].pixel_count() > 0)
            relative_errors += figure_html({"", write_png(false_colour_magnitude(relative[i], relative_scale), name + "_relerror.png"),
                                            r.algorithm + " relative error",
                                            fmt::format("<b>{}</b><br>median {:.3g}, 90th percentile {:.3g}", xml_escape(r.algorithm),
                                                        relative_percentiles[i].first, relative_percentiles[i].second)},
                                           w, h);
        for (size_t k = 0; k < data.crops.size(); ++k)
            inset_rows[k] += inset_html(write_exposures(crop(r.mean, data.crops[k]), fmt::format("{}_crop{}", name, k)), data.crops[k],
                                        fmt::format("<b>{}</b>", xml_escape(r.algorithm)));
    }
    for (size_t k = 0; k < data.crops.size(); ++k) {
        const PixelRect& c = data.crops[k];
        insets += fmt::format("<p>Crop {}: {}x{} pixels at ({}, {}), magnified {}x.</p>\n<div class=\"grid\">\n{}</div>\n", k + 1, c.width,
                              c.height, c.x, c.y, std::max(1, 192 / c.width), inset_rows[k]);
    }
    const std::string bar = write_png(diverging_colour_bar(256, 1), "colourbar.png");
    const std::string se_bar = write_png(sequential_colour_bar(256, 1), "colourbar_stderr.png");

    std::string table =
        "<table>\n<tr><th>algorithm</th><th>spp</th><th>seconds</th><th>Msamples/s</th><th>RMSE</th><th>relMSE</th>"
        "<th>efficiency 1/(MSE·s)</th><th>mean diff (R, G, B)</th><th>NaN/Inf samples</th></tr>\n";
    std::string table_csv = "algorithm,spp,seconds,msamples_per_second,rmse,relmse,efficiency,mean_diff_r,mean_diff_g,mean_diff_b,invalid_samples\n";
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        const ImageDifference& d = diffs[i];
        const double msps = r.stats.seconds > 0 ? double(r.stats.samples) / r.stats.seconds * 1e-6 : 0.0;
        table += fmt::format("<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.2f}</td><td{}>{:.4g}</td><td>{:.4g}</td><td{}>{:.4g}</td>"
                             "<td>{:+.2e}, {:+.2e}, {:+.2e}</td><td>{}</td></tr>\n",
                             xml_escape(r.algorithm), r.stats.spp, r.stats.seconds, msps, i == best ? " class=\"best\"" : "", rmses[i],
                             d.all.relmse, i == most_efficient ? " class=\"best\"" : "", efficiencies[i], d.channel[0].mean_diff,
                             d.channel[1].mean_diff, d.channel[2].mean_diff, r.stats.invalid_samples);
        table_csv += fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", csv_field(r.algorithm), r.stats.spp,
                                 r.stats.seconds, msps, rmses[i], d.all.relmse, efficiencies[i], d.channel[0].mean_diff,
                                 d.channel[1].mean_diff, d.channel[2].mean_diff, r.stats.invalid_samples);
    }
    table += "</table>\n";
    const std::string table_link = write_text(table_csv, "table.csv");

    std::vector<PlotSeries> by_time, by_spp;
    std::string curves_csv = "algorithm,seconds,spp,rmse\n";
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        PlotSeries t{r.algorithm, series_colour(i), {}}, n{r.algorithm, series_colour(i), {}};
        for (const ConvergencePoint& p : r.convergence) {
            t.points.push_back({p.seconds, p.rmse});
            n.points.push_back({double(p.spp), p.rmse});
            curves_csv += fmt::format("{},{:.6g},{},{:.6g}\n", csv_field(r.algorithm), p.seconds, p.spp, p.rmse);
        }
        by_time.push_back(std::move(t));
        by_spp.push_back(std::move(n));
    }
    const std::string curves_link = write_text(curves_csv, "convergence.csv");
    const std::string svg = log_log_svg({"RMSE against the reference over render time", "render time (s)", "RMSE", 640, 400, true}, by_time);
    const std::string svg_spp =
        log_log_svg({"RMSE against the reference over samples per pixel", "samples per pixel", "RMSE", 640, 400, true}, by_spp);
    write_text(svg, "convergence.svg");
    write_text(svg_spp, "convergence_spp.svg");

    std::string notes;
    for (const std::string& n : data.notes) notes += "<p class=\"note\">" + xml_escape(n) + "</p>\n";
    const std::string inset_section =
        insets.empty() ? "" : "<h2>Insets</h2>\n<p>The crops outlined in yellow on the images above, side by side.</p>\n" + insets;
    // ppg with --guide-pixel: the learned guiding density, each on its own scale (its largest value).
    std::string guides;
    for (const ReportRender& r : data.renders) {
        if (r.guide_note.empty()) continue;
        if (r.guide_map.pixel_count() == 0) {
            guides += fmt::format("<p><b>{}</b>: {}; no distribution there.</p>\n", xml_escape(r.algorithm), xml_escape(r.guide_note));
            continue;
        }
        float top = 0;
        for (size_t p = 0; p < r.guide_map.pixel_count(); ++p) top = std::max(top, r.guide_map[p][0]);
        const std::string caption =
            top > 0 ? fmt::format("<b>{}</b><br>{}<br>largest density {:.3g} sr<sup>−1</sup>", xml_escape(r.algorithm), xml_escape(r.guide_note), top)
                    : fmt::format("<b>{}</b><br>{}<br>nothing learned there: BSDF sampling only", xml_escape(r.algorithm), xml_escape(r.guide_note));
        guides += figure_html({"", write_png(false_colour_magnitude(r.guide_map, top > 0 ? top : 1.0f), slug(r.algorithm) + "_guide.png"),
                               r.algorithm + " guiding distribution", caption},
                              r.guide_map.width(), r.guide_map.height());
    }
    const std::string guide_section =
        guides.empty() ? ""
                       : "<h2>What the guide learned</h2>\n<p>The directional distribution ppg learned in the spatial cell of the "
                         "point (its quadtree, or with --guiding vmm its mixture of lobes), over the sphere of directions in the "
                         "quadtree's cylindrical coordinates: columns are the azimuth from +x (left) towards "
                         "+y, rows the cosine of the angle from +z (top: up the z axis, bottom: down it), an equal-area map, so a "
                         "region's share of the picture is its share of directions; bright where the training paths found light coming "
                         "from.</p>\n<div class=\"grid\">\n" +
                             guides + "</div>\n";
    const std::string se_section =
        std_errors.empty()
            ? ""
            : fmt::format("<h2>Per-pixel standard error</h2>\n<p>The standard error of each pixel's mean, from its samples' variance (the "
                          "mean of its three channels), on one scale for all: where an estimator is noisy. Red: NaN/Inf.</p>\n"
                          "<div class=\"bar\"><span>0</span><img src=\"{}\" alt=\"colour scale\"><span>{:.3g}</span></div>\n"
                          "<div class=\"grid\">\n{}</div>\n",
                          xml_escape(se_bar), se_scale, std_errors) +
                  (relative_errors.empty()
                       ? ""
                       : fmt::format("<h2>Per-pixel relative error</h2>\n<p>Each pixel's standard error over the reference's value: how "
                                     "evenly an estimator converges. Markov chains (pssmlt, mmlt) spend their mutations in proportion to "
                                     "brightness, so their dim regions lag; bdpt's error follows its strategies instead. The standard "
                                     "errors are over independent passes (every estimator's passes are, pssmlt's and mmlt's too: each "
                                     "pass starts its chains afresh), so one render measures them. Black: pixels darker than 1% of the "
                                     "reference's mean.</p>\n"
                                     "<div class=\"bar\"><span>0</span><img src=\"{}\" alt=\"colour scale\"><span>{:.3g}</span></div>\n"
                                     "<div class=\"grid\">\n{}</div>\n",
                                     xml_escape(se_bar), relative_scale, relative_errors)) +
        guide_section;

    const std::string html = fmt::format(
        R"(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>pathlab report: {title}</title>
<link rel="icon" href="data:,">
<style>{style}</style>
</head>
<body>
<h1>pathlab report: {title}</h1>
<p class="meta">{budget}; {w}x{h} pixels; reference: {reference_note}<br>pathlab {version}, {date}<br><code>{command}</code></p>
{notes}<div class="controls">
<label>Exposure <input type="range" id="exposure" min="{emin}" max="{emax}" step="1" value="0"></label> <span id="exposure-value">0</span> stops
&nbsp;·&nbsp; <label>Zoom <select id="zoom"><option value="4">4x</option><option value="8" selected>8x</option><option value="16">16x</option><option value="32">32x</option></select></label>
&nbsp;·&nbsp; click an image to zoom in at that pixel (all images follow), click again or press Esc to zoom out &nbsp;<span id="pixel"></span>
</div>
<h2>Images</h2>
<div class="grid">
{images}</div>
{insets}<h2>Error against the reference</h2>
<p>Luminance of each render minus the reference's, on one scale for all (blue: darker than the reference, red: brighter;
green: NaN/Inf). Noise shows as speckle; bias as a coloured region.</p>
<div class="bar"><span>−{scale:.3g}</span><img src="{bar}" alt="colour scale"><span>+{scale:.3g}</span></div>
<div class="grid">
{errors}</div>
{se_section}<h2>Statistics</h2>
<p>RMSE over all pixels and channels against the reference{rmse_note}; relMSE = mean((render − reference)² / (reference² + 0.01));
efficiency = 1 / (MSE × seconds), the inverse of the time an estimator needs for a given error (higher is better; it stays
constant as an unbiased estimator converges). Lowest RMSE and highest efficiency in bold.
As CSV: <a href="{table_csv}">the table</a>, <a href="{curves_csv}">the convergence curves</a>.</p>
{table}
<h2>Convergence</h2>
<p>RMSE against the reference at checkpoints of each progressive render (log-log), over time and over samples per pixel.
Unbiased estimators fall with slope −1/2 (error ∝ 1/√time); a lower line is a more efficient estimator; a line that flattens
out is biased, or has reached the reference's own noise.</p>
<div class="plots">
{svg}{svg_spp}</div>
<script>{script}</script>
</body>
</html>
)",
        fmt::arg("title", xml_escape(data.title)), fmt::arg("style", kStyle), fmt::arg("budget", xml_escape(data.budget)),
        fmt::arg("w", w), fmt::arg("h", h), fmt::arg("reference_note", xml_escape(data.reference_note)),
        fmt::arg("version", PATHLAB_VERSION), fmt::arg("date", utc_now()), fmt::arg("command", xml_escape(data.command)),
        fmt::arg("notes", notes), fmt::arg("emin", kReportMinExposure), fmt::arg("emax", kReportMaxExposure),
        fmt::arg("images", images), fmt::arg("insets", inset_section), fmt::arg("scale", scale), fmt::arg("bar", xml_escape(bar)),
        fmt::arg("errors", errors), fmt::arg("se_section", se_section),
        fmt::arg("rmse_note", data.reference_se.pixel_count() ? " with the reference's own noise (its mean squared standard error) removed" : ""),
        fmt::arg("table_csv", xml_escape(table_link)), fmt::arg("curves_csv", xml_escape(curves_link)), fmt::arg("table", table),
        fmt::arg("svg", svg), fmt::arg("svg_spp", svg_spp), fmt::arg("script", kScript));
    write_text_file(html_path, html);
    return written;
}

}  // namespace pathlab
