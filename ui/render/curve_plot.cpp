#include "render/curve_plot.h"

#include "render/offscreen_png.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <stdexcept>

namespace liversim {

std::array<unsigned char, 3> curve_series_colour(std::size_t index) {
  // Saturated and far apart, so that overlapping curves stay distinguishable (and testable).
  static constexpr std::array<std::array<unsigned char, 3>, 6> kPalette{{
      {31, 119, 180},   // blue
      {214, 39, 40},    // red
      {44, 160, 44},    // green
      {148, 103, 189},  // purple
      {255, 127, 14},   // orange
      {23, 190, 207}    // cyan
  }};
  return kPalette[index % kPalette.size()];
}

namespace {

// An offscreen chart with a title, axis titles and a legend, white background.
struct PlotWindow {
  PlotWindow(const std::string& title, const std::string& x_label, const std::string& y_label,
             int width, int height) {
    view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
    vtkRenderWindow* window = view->GetRenderWindow();
    window->SetOffScreenRendering(1);
    window->SetSize(width, height);
    window->SetMultiSamples(0);
    view->GetScene()->AddItem(chart);
    chart->SetTitle(title);
    chart->GetTitleProperties()->SetFontSize(16);
    chart->SetShowLegend(true);
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::CENTER);
    chart->GetAxis(vtkAxis::BOTTOM)->SetTitle(x_label);
    vtkAxis* y_axis = chart->GetAxis(vtkAxis::LEFT);
    y_axis->SetTitle(y_label);
    // The default fixed notation prints small strains (1e-4) as 0.00.
    y_axis->SetNotation(vtkAxis::PRINTF_NOTATION);
    y_axis->SetLabelFormat("%g");
  }
  vtkNew<vtkContextView> view;
  vtkNew<vtkChartXY> chart;
};

}  // namespace

void write_curve_plot_png(const std::filesystem::path& file, const std::string& title,
                          const std::string& x_label, const std::string& y_label,
                          const std::vector<double>& x, const std::vector<CurveSeries>& series,
                          int width, int height) {
  if (series.empty()) throw std::invalid_argument("a curve plot needs at least one series");
  for (const CurveSeries& s : series)
    if (s.y.size() != x.size())
      throw std::invalid_argument("series '" + s.name + "' has " + std::to_string(s.y.size()) +
                                  " values for " + std::to_string(x.size()) + " abscissae");
  check_offscreen_png_target(file, "plot");

  vtkNew<vtkTable> table;
  vtkNew<vtkDoubleArray> x_column;
  x_column->SetName(x_label.c_str());
  table->AddColumn(x_column);
  for (const CurveSeries& s : series) {
    vtkNew<vtkDoubleArray> column;
    column->SetName(s.name.c_str());
    table->AddColumn(column);
  }
  table->SetNumberOfRows(static_cast<vtkIdType>(x.size()));
  for (std::size_t row = 0; row < x.size(); ++row) {
    table->SetValue(static_cast<vtkIdType>(row), 0, x[row]);
    for (std::size_t i = 0; i < series.size(); ++i)
      table->SetValue(static_cast<vtkIdType>(row), static_cast<vtkIdType>(i + 1), series[i].y[row]);
  }

  PlotWindow plot(title, x_label, y_label, width, height);
  vtkChartXY* chart = plot.chart;
  for (std::size_t i = 0; i < series.size(); ++i) {
    vtkPlot* line = chart->AddPlot(vtkChart::LINE);
    line->SetInputData(table, 0, static_cast<vtkIdType>(i + 1));
    const auto rgb = curve_series_colour(i);
    line->SetColor(rgb[0], rgb[1], rgb[2], 255);
    line->SetWidth(series[i].dashed ? 2.0f : 3.0f);
    if (series[i].dashed) line->GetPen()->SetLineType(vtkPen::DASH_LINE);
  }

  write_window_png(plot.view->GetRenderWindow(), file);
}

void write_scatter_plot_png(const std::filesystem::path& file, const std::string& title,
                            const std::string& x_label, const std::string& y_label,
                            const std::vector<ScatterSeries>& series, bool log_x, bool log_y,
                            int width, int height) {
  if (series.empty()) throw std::invalid_argument("a scatter plot needs at least one series");
  for (const ScatterSeries& s : series)
    if (s.x.size() != s.y.size())
      throw std::invalid_argument("series '" + s.name + "' has " + std::to_string(s.y.size()) +
                                  " values for " + std::to_string(s.x.size()) + " abscissae");
  check_offscreen_png_target(file, "plot");
  PlotWindow plot(title, x_label, y_label, width, height);
  plot.chart->GetAxis(vtkAxis::BOTTOM)->SetLogScale(log_x);
  plot.chart->GetAxis(vtkAxis::LEFT)->SetLogScale(log_y);
  plot.chart->GetAxis(vtkAxis::BOTTOM)->SetNotation(vtkAxis::PRINTF_NOTATION);
  plot.chart->GetAxis(vtkAxis::BOTTOM)->SetLabelFormat("%g");
  std::vector<vtkSmartPointer<vtkTable>> tables;  // kept alive until rendered
  for (std::size_t i = 0; i < series.size(); ++i) {
    auto table = vtkSmartPointer<vtkTable>::New();
    vtkNew<vtkDoubleArray> x_column, y_column;
    x_column->SetName((series[i].name + " x").c_str());
    y_column->SetName(series[i].name.c_str());
    for (std::size_t k = 0; k < series[i].x.size(); ++k) {
      const double x = series[i].x[k], y = series[i].y[k];
      if ((log_x && !(x > 0.0)) || (log_y && !(y > 0.0))) continue;
      x_column->InsertNextValue(x);
      y_column->InsertNextValue(y);
    }
    table->AddColumn(x_column);
    table->AddColumn(y_column);
    tables.push_back(table);
    const auto rgb = curve_series_colour(i);
    vtkPlot* line = plot.chart->AddPlot(vtkChart::LINE);
    line->SetInputData(table, 0, 1);
    line->SetColor(rgb[0], rgb[1], rgb[2], 255);
    line->SetWidth(2.0f);
    vtkPlot* points = plot.chart->AddPlot(vtkChart::POINTS);
    points->SetInputData(table, 0, 1);
    points->SetColor(rgb[0], rgb[1], rgb[2], 255);
    points->SetLegendVisibility(false);
  }
  write_window_png(plot.view->GetRenderWindow(), file);
}

}  // namespace liversim
