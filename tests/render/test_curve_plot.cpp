// write_curve_plot_png: the PNG has the requested size, shows every series in its own colour (also
// when a dashed reference curve lies exactly on a computed one), and bad input fails with a
// message. Needs an X display (Debian's VTK has no EGL or OSMesa): run it under
//   xvfb-run -a -s "-screen 0 1280x1024x24" ctest -R Plot
#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "render/curve_plot.h"

namespace fs = std::filesystem;
using liversim::curve_series_colour;
using liversim::CurveSeries;
using liversim::write_curve_plot_png;

namespace {

const fs::path kOutputDir = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "curve_plot";

struct Picture {
  int width = 0, height = 0;
  vtkNew<vtkImageData> pixels;
};

void read_png(const fs::path& file, Picture& picture) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(file.string().c_str());
  reader->Update();
  picture.pixels->DeepCopy(reader->GetOutput());
  int dims[3];
  picture.pixels->GetDimensions(dims);
  picture.width = dims[0];
  picture.height = dims[1];
}

// Pixels within a small distance of `rgb`; antialiased edges are blends, the line cores are not.
int count_pixels_of_colour(const Picture& picture, const std::array<unsigned char, 3>& rgb) {
  int count = 0;
  for (int y = 0; y < picture.height; ++y)
    for (int x = 0; x < picture.width; ++x) {
      int distance = 0;
      for (int c = 0; c < 3; ++c)
        distance += std::abs(
            static_cast<int>(picture.pixels->GetScalarComponentAsDouble(x, y, 0, c)) - rgb[c]);
      if (distance <= 30) ++count;
    }
  return count;
}

std::vector<double> sampled(double (*f)(double), const std::vector<double>& x) {
  std::vector<double> y;
  for (double xi : x) y.push_back(f(xi));
  return y;
}

class CurvePlot : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* display = std::getenv("DISPLAY");
    ASSERT_TRUE(display != nullptr && *display != '\0')
        << "DISPLAY is not set. This plotting test needs an X server (Debian's VTK has no EGL or "
           "OSMesa); run it under\n  xvfb-run -a -s \"-screen 0 1280x1024x24\" ctest -R Plot";
    fs::create_directories(kOutputDir);
    for (int i = 0; i <= 200; ++i) x_.push_back(0.05 * i);
  }
  std::vector<double> x_;
};

TEST_F(CurvePlot, WritesPngOfRequestedSizeWithEverySeriesInItsColour) {
  const fs::path file = kOutputDir / "two_series.png";
  fs::remove(file);
  write_curve_plot_png(file, "sin and cos", "t (s)", "value", x_,
                       {{"sin", sampled([](double t) { return std::sin(t); }, x_)},
                        {"cos", sampled([](double t) { return std::cos(t); }, x_)}},
                       640, 400);
  ASSERT_TRUE(fs::exists(file));
  Picture picture;
  read_png(file, picture);
  EXPECT_EQ(picture.width, 640);
  EXPECT_EQ(picture.height, 400);
  // A line of ~600 pixels at width 3 shows well over 500 pixels of its colour; the legend's
  // swatches alone would not reach that.
  EXPECT_GT(count_pixels_of_colour(picture, curve_series_colour(0)), 500) << file;
  EXPECT_GT(count_pixels_of_colour(picture, curve_series_colour(1)), 500) << file;
  EXPECT_GT(count_pixels_of_colour(picture, {255, 255, 255}), 640 * 400 / 2) << "background";
}

// The CLI's case: an analytic curve on top of the simulated one. The dashes leave the line under
// them visible.
TEST_F(CurvePlot, DashedReferenceOnTopLeavesTheCurveUnderneathVisible) {
  const fs::path file = kOutputDir / "overlapping.png";
  fs::remove(file);
  const std::vector<double> y = sampled([](double t) { return std::exp(-t); }, x_);
  write_curve_plot_png(file, "relaxation", "time (s)", "stress (Pa)", x_,
                       {{"simulated", y, false}, {"analytic", y, true}}, 800, 500);
  Picture picture;
  read_png(file, picture);
  EXPECT_EQ(picture.width, 800);
  EXPECT_EQ(picture.height, 500);
  EXPECT_GT(count_pixels_of_colour(picture, curve_series_colour(0)), 200) << file;
  EXPECT_GT(count_pixels_of_colour(picture, curve_series_colour(1)), 200) << file;
}

TEST_F(CurvePlot, MissingFolderFailsWithMessage) {
  try {
    write_curve_plot_png("/nonexistent/folder/plot.png", "t", "x", "y", x_, {{"a", x_}}, 320, 200);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(CurvePlotInput, SeriesOfWrongLengthIsRejected) {
  EXPECT_THROW(write_curve_plot_png(kOutputDir / "bad.png", "t", "x", "y", {0.0, 1.0},
                                    {{"short", {1.0}}}, 320, 200),
               std::invalid_argument);
  EXPECT_THROW(write_curve_plot_png(kOutputDir / "bad.png", "t", "x", "y", {0.0}, {}, 320, 200),
               std::invalid_argument);
}

// VTK aborts the process when it cannot open a display; the plot must refuse first, with a hint.
TEST(CurvePlotInput, NoDisplayFailsWithMessage) {
  const char* display = std::getenv("DISPLAY");
  const std::string saved = display ? display : "";
  unsetenv("DISPLAY");
  std::string message;
  try {
    write_curve_plot_png(kOutputDir / "no_display.png", "t", "x", "y", {0.0}, {{"a", {1.0}}}, 320,
                         200);
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  if (display) setenv("DISPLAY", saved.c_str(), 1);
  EXPECT_NE(message.find("no X display"), std::string::npos) << message;
  EXPECT_NE(message.find("xvfb-run"), std::string::npos) << message;
}

}  // namespace
