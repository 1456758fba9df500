// The equal-time (or equal-spp) comparison report: one self-contained HTML page that works
// offline (no fonts, scripts or styles fetched) with its images in a directory beside it
// ("report.html" -> "report_files/"):
//  - every render and the reference as tone-mapped PNGs at exposures -4..+4 stops (an
//    exposure slider swaps them; tone mapping stays pathlab's own sRGB encoding);
//  - click-to-zoom at pixel level (CSS image-rendering: pixelated), synchronised over all
//    images, so the same pixels of every estimator are seen side by side;
//  - inset crops (--crop X,Y,W,H) of every image side by side, magnified, outlined on the images;
//  - per algorithm a false-colour signed error image (render - reference luminance, one scale
//    for all, judge/false_colour.hpp) and a per-pixel standard-error image (one scale for all);
//  - a table of spp, time, RMSE, relMSE, mean difference and the efficiency 1/(MSE x seconds),
//    exported with the curves as CSV (report_files/table.csv, convergence.csv);
//  - RMSE against time and against samples per pixel (log-log SVG) from the renders' checkpoints.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "image/image.hpp"
#include "job/renderer.hpp"

namespace pathlab {

struct ConvergencePoint {
    double seconds = 0;
    uint64_t spp = 0;
    double rmse = 0;  // against the reference, its own noise removed
};

struct ReportRender {
    std::string algorithm;
    Image mean;
    Image std_error;  // per-pixel standard errors of the mean (may be empty)
    RenderStats stats;
    std::vector<ConvergencePoint> convergence;
    // ppg with --guide-pixel: the density its SD-tree learned at that pixel's first hit
    // (integrators/guiding/guide_map.hpp: per steradian over the equal-area square of directions;
    // empty when none), and what it shows.
    Image guide_map;
    std::string guide_note;
};

struct ReportData {
    std::string title;           // e.g. "scene 3 ceiling-glossy"
    std::string budget;          // e.g. "equal time: 5 s per algorithm"
    std::string reference_note;  // where the reference came from (in full)
    std::string reference_label; // the same in a few words, under its image
    Image reference;
    Image reference_se;          // may be empty (exact, or unknown)
    std::vector<ReportRender> renders;
    std::vector<std::string> notes;  // shown prominently (e.g. "interrupted: ...")
    std::string command;             // the command line that made the report
    std::vector<PixelRect> crops;    // inset crops (inside the image)
};

constexpr int kReportMinExposure = -4, kReportMaxExposure = 4;

// Writes the page and its images; returns every file written (the HTML first). Throws
// ImageIoError when a file cannot be written.
std::vector<std::string> write_html_report(const ReportData& data, const std::string& html_path);

// The directory of a report's images: "dir/report.html" -> "dir/report_files".
std::string report_files_dir(const std::string& html_path);

}  // namespace pathlab
