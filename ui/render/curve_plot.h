#pragma once
// Line plots of curves written to PNG, for material curves and verification reports. VTK only (no
// Qt), rendered offscreen like the liver screenshots.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace liversim {

struct CurveSeries {
  std::string name;       // shown in the legend
  std::vector<double> y;  // one value per x
  bool dashed = false;    // e.g. a reference curve drawn over a computed one
};

// RGB colour of the series at `index` in the plot (the palette repeats after a few series).
std::array<unsigned char, 3> curve_series_colour(std::size_t index);

// Writes a PNG of width x height pixels: the series as lines over the common abscissa `x`, a
// legend, axis titles and a title. Needs an X display (Debian's VTK has no EGL or OSMesa): under
// no display, run it inside xvfb-run. Throws std::invalid_argument when there is no series or a
// series does not have one value per x, and std::runtime_error naming the problem when there is
// no display or the file cannot be written (no partial file is left).
void write_curve_plot_png(const std::filesystem::path& file, const std::string& title,
                          const std::string& x_label, const std::string& y_label,
                          const std::vector<double>& x, const std::vector<CurveSeries>& series,
                          int width, int height);

// A set of (x, y) points of its own, drawn as markers joined by a line, e.g. one integrator's runs
// in an error-versus-cost plot.
struct ScatterSeries {
  std::string name;
  std::vector<double> x;
  std::vector<double> y;
};

// Like write_curve_plot_png, for series with their own abscissae; logarithmic axes on request
// (non-positive values are left out of a logarithmic plot). Throws std::invalid_argument when
// there is no series or a series' x and y differ in length.
void write_scatter_plot_png(const std::filesystem::path& file, const std::string& title,
                            const std::string& x_label, const std::string& y_label,
                            const std::vector<ScatterSeries>& series, bool log_x, bool log_y,
                            int width, int height);

}  // namespace liversim
