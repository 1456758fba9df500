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
.view img { position: absolute; left: 0; top: 0; transform-origin: 0 0; image-rendering: pixelated; }
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
      const img = view.querySelector('img');
      const w = Number(view.dataset.w), h = Number(view.dataset.h);
      const dw = view.clientWidth, dh = view.clientHeight, base = dw / w;
      let s = base, tx = 0, ty = 0;
      if (focus) {
        s = base * Number(zoomSelect.value);
        tx = Math.min(0, Math.max(dw - w * s, dw / 2 - (focus.x + 0.5) * s));
        ty = Math.min(0, Math.max(dh - h * s, dh / 2 - (focus.y + 0.5) * s));
      }
      img.style.transform = 'translate(' + tx + 'px, ' + ty + 'px) scale(' + s + ')';
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

std::string figure_html(const Figure& f, int w, int h) {
    const int dw = std::min(w, kMaxDisplayWidth);
    const int dh = int(std::lround(double(h) * dw / w));
    const std::string img = f.stem.empty()
                                ? fmt::format("<img src=\"{}\" width=\"{}\" height=\"{}\" alt=\"{}\">", xml_escape(f.src), w, h, xml_escape(f.alt))
                                : fmt::format("<img data-stem=\"{0}\" src=\"{0}_e0.png\" width=\"{1}\" height=\"{2}\" alt=\"{3}\">",
                                              xml_escape(f.stem), w, h, xml_escape(f.alt));
    return fmt::format("<figure style=\"width:{}px\"><div class=\"view\" style=\"width:{}px;height:{}px\" data-w=\"{}\" data-h=\"{}\">{}</div>"
                       "<figcaption>{}</figcaption></figure>\n",
                       dw, dw, dh, w, h, img, f.caption);
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
    std::vector<std::string> written{html_path};
    const auto write_png = [&](const Image8& img, const std::string& name) {
        write_png8(img, (files_dir / name).string());
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
    // 99th percentiles of |difference| (so the noisiest render just saturates).
    std::vector<ImageDifference> diffs;
    std::vector<double> rmses;
    double scale = 0;
    for (const ReportRender& r : data.renders) {
        diffs.push_back(compare_images(r.mean, data.reference));
        rmses.push_back(rmse_against_reference(r.mean, data.reference, data.reference_se));
        scale = std::max(scale, difference_scale(r.mean, data.reference));
    }
    if (!(scale > 0)) scale = 1;
    const size_t best = rmses.empty() ? 0 : size_t(std::min_element(rmses.begin(), rmses.end()) - rmses.begin());

    std::string images, errors;
    images += figure_html({write_exposures(data.reference, "reference"), "", "reference",
                           "<b>reference</b><br>" + xml_escape(data.reference_label)},
                          w, h);
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        const std::string name = slug(r.algorithm);
        const std::string caption = fmt::format("<b>{}</b><br>{} spp, {:.2f} s{}<br>RMSE {:.4g}", xml_escape(r.algorithm), r.stats.spp,
                                                r.stats.seconds, r.stats.interrupted ? " (interrupted)" : "", rmses[i]);
        images += figure_html({write_exposures(r.mean, name), "", r.algorithm, caption}, w, h);
        errors += figure_html({"", write_png(false_colour_difference(r.mean, data.reference, scale), name + "_error.png"),
                               r.algorithm + " error", fmt::format("<b>{}</b> − reference", xml_escape(r.algorithm))},
                              w, h);
    }
    const std::string bar = write_png(diverging_colour_bar(256, 1), "colourbar.png");

    std::string table =
        "<table>\n<tr><th>algorithm</th><th>spp</th><th>seconds</th><th>Msamples/s</th><th>RMSE</th><th>relMSE</th>"
        "<th>mean diff (R, G, B)</th><th>NaN/Inf samples</th></tr>\n";
    for (size_t i = 0; i < data.renders.size(); ++i) {
        const ReportRender& r = data.renders[i];
        const ImageDifference& d = diffs[i];
        table += fmt::format("<tr><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.2f}</td><td{}>{:.4g}</td><td>{:.4g}</td>"
                             "<td>{:+.2e}, {:+.2e}, {:+.2e}</td><td>{}</td></tr>\n",
                             xml_escape(r.algorithm), r.stats.spp, r.stats.seconds,
                             r.stats.seconds > 0 ? double(r.stats.samples) / r.stats.seconds * 1e-6 : 0.0,
                             i == best ? " class=\"best\"" : "", rmses[i], d.all.relmse, d.channel[0].mean_diff,
                             d.channel[1].mean_diff, d.channel[2].mean_diff, r.stats.invalid_samples);
    }
    table += "</table>\n";

    std::vector<PlotSeries> series;
    for (size_t i = 0; i < data.renders.size(); ++i)
        series.push_back({data.renders[i].algorithm, series_colour(i), data.renders[i].convergence});
    const std::string svg = log_log_svg({"RMSE against the reference over render time", "render time (s)", "RMSE", 720, 420, true}, series);
    write_text_file((files_dir / "convergence.svg").string(), svg);
    written.push_back((files_dir / "convergence.svg").string());

    std::string notes;
    for (const std::string& n : data.notes) notes += "<p class=\"note\">" + xml_escape(n) + "</p>\n";

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
<h2>Error against the reference</h2>
<p>Luminance of each render minus the reference's, on one scale for all (blue: darker than the reference, red: brighter;
green: NaN/Inf). Noise shows as speckle; bias as a coloured region.</p>
<div class="bar"><span>−{scale:.3g}</span><img src="{bar}" alt="colour scale"><span>+{scale:.3g}</span></div>
<div class="grid">
{errors}</div>
<h2>Statistics</h2>
<p>RMSE over all pixels and channels against the reference{rmse_note}; relMSE = mean((render − reference)² / (reference² + 0.01)).
Lowest RMSE in bold.</p>
{table}
<h2>Convergence</h2>
<p>RMSE against the reference at checkpoints of each progressive render (log-log). Unbiased estimators fall with slope −1/2
(error ∝ 1/√time); a lower line is a more efficient estimator; a line that flattens out is biased, or has reached the
reference's own noise.</p>
{svg}
<script>{script}</script>
</body>
</html>
)",
        fmt::arg("title", xml_escape(data.title)), fmt::arg("style", kStyle), fmt::arg("budget", xml_escape(data.budget)),
        fmt::arg("w", w), fmt::arg("h", h), fmt::arg("reference_note", xml_escape(data.reference_note)),
        fmt::arg("version", PATHLAB_VERSION), fmt::arg("date", utc_now()), fmt::arg("command", xml_escape(data.command)),
        fmt::arg("notes", notes), fmt::arg("emin", kReportMinExposure), fmt::arg("emax", kReportMaxExposure),
        fmt::arg("images", images), fmt::arg("scale", scale), fmt::arg("bar", xml_escape(bar)), fmt::arg("errors", errors),
        fmt::arg("rmse_note", data.reference_se.pixel_count() ? " with the reference's own noise (its mean squared standard error) removed" : ""),
        fmt::arg("table", table), fmt::arg("svg", svg), fmt::arg("script", kScript));
    write_text_file(html_path, html);
    return written;
}

}  // namespace pathlab
