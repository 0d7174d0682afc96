#include "simulation_status.h"

#include "accuracy_panel.h"

#include <QCoreApplication>

#include <cmath>

namespace liversim {
// The status bar is the main window's: its strings are translated in its context.
namespace {

// A positive number with two or three significant digits and no exponent: 0.81, 2.6, 15, 480.
QString formatAmount(double value) {
  const double size = std::abs(value);
  return QString::number(value, 'f', size < 1.0 ? 2 : size < 10.0 ? 1 : 0);
}

}  // namespace

QString simulationStatusText(const SimulationStatus& status) {
  const RealtimeStats& stats = status.stats;
  QString text =
      QCoreApplication::translate("liversim::MainWindow",
                                  "%1 fps | %2 steps/s | real-time factor %3 | step %4 ms")
          .arg(status.framesPerSecond, 0, 'f', 0)
          .arg(stats.steps_per_second, 0, 'f', 0)
          .arg(stats.real_time_factor, 0, 'f', 2)
          .arg(stats.step_s * 1e3, 0, 'f', 3);
  if (stats.behind)
    text += QCoreApplication::translate("liversim::MainWindow", " | slower than real time");
  text += QCoreApplication::translate("liversim::MainWindow", " | ") + accuracyStatusText(stats);
  // What the trainee acts on comes first: a window narrower than the whole line cuts its end off
  // (at 1280 px the pieces cut free and the Remove Specimen hint were not shown).
  QString trainee;  // each part begins with the separator
  if (status.freeBodies > 0)
    trainee += QCoreApplication::translate(
        "liversim::MainWindow", " | %n piece(s) cut free: lift out or Session ▸ Remove Specimen",
        nullptr, status.freeBodies);
  if (status.specimensTakenOut > 0)
    trainee += QCoreApplication::translate("liversim::MainWindow", " | %n specimen(s) taken out",
                                           nullptr, status.specimensTakenOut);
  if (status.resectedVolume_m3 > 0.0)
    trainee += QCoreApplication::translate("liversim::MainWindow", " | resected %1 mL")
                   .arg(status.resectedVolume_m3 * 1e6, 0, 'f', 1);
  if (status.pullingForce_n)
    trainee += QCoreApplication::translate("liversim::MainWindow", " | pulling %1 N")
                   .arg(*status.pullingForce_n, 0, 'f', 2);
  const QString separator = QCoreApplication::translate("liversim::MainWindow", " | ");
  if (trainee.startsWith(separator)) trainee.remove(0, separator.size());
  if (!trainee.isEmpty()) text = trainee + separator + text;
  // The step guards: what went wrong and what the simulation did about it.
  if (stats.halted)
    text = QCoreApplication::translate(
               "liversim::MainWindow",
               "Simulation halted: %1; every retry with shorter steps failed. Apply a setting in "
               "the Accuracy panel (another integrator or a shorter step) to go on from the last "
               "good state. | ")
               .arg(healthProblemText(stats.last_problem)) +
           text;
  else if (stats.rollbacks > 0 || stats.rejected_inputs > 0)
    text += QCoreApplication::translate("liversim::MainWindow",
                                        " | recovered %1 times, refused %2 inputs (last: %3)")
                .arg(stats.rollbacks)
                .arg(stats.rejected_inputs)
                .arg(healthProblemText(stats.last_problem));
  if (stats.energy_created)
    text += QCoreApplication::translate(
        "liversim::MainWindow",
        " | energy books: the scheme is creating energy (choose a shorter step or an "
        "implicit scheme)");
  return text;
}

QString healthProblemText(HealthProblem problem) {
  switch (problem) {
    case HealthProblem::none:
      return QCoreApplication::translate("liversim::MainWindow", "no problem");
    case HealthProblem::non_finite_input:
      return QCoreApplication::translate("liversim::MainWindow", "a tool input was not a number");
    case HealthProblem::non_finite_position:
      return QCoreApplication::translate("liversim::MainWindow",
                                         "a node position became not a number");
    case HealthProblem::non_finite_velocity:
      return QCoreApplication::translate("liversim::MainWindow",
                                         "a node velocity became not a number");
    case HealthProblem::runaway_speed:
      return QCoreApplication::translate("liversim::MainWindow", "a node moved implausibly fast");
    case HealthProblem::runaway_energy:
      return QCoreApplication::translate("liversim::MainWindow",
                                         "a node gained more energy than the tools put in");
    case HealthProblem::solver_failed:
      return QCoreApplication::translate("liversim::MainWindow",
                                         "an implicit step did not converge");
    case HealthProblem::step_collapsed:
      return QCoreApplication::translate(
          "liversim::MainWindow",
          "the step fell below a thousandth of its value at rest (tissue drawn or crushed past "
          "what the step can follow)");
  }
  return QCoreApplication::translate("liversim::MainWindow", "unknown problem");
}

// Below a picometre it is round-off, not a number worth reading.
QString formatError(double error_m) {
  if (std::isnan(error_m)) return QCoreApplication::translate("liversim::MainWindow", "n/a");
  const double size = std::abs(error_m);
  if (size < 1e-12) return QCoreApplication::translate("liversim::MainWindow", "< 1 pm");
  if (size < 1e-9)
    return QCoreApplication::translate("liversim::MainWindow", "≈ %1 pm")
        .arg(formatAmount(error_m * 1e12));
  if (size < 1e-6)
    return QCoreApplication::translate("liversim::MainWindow", "≈ %1 nm")
        .arg(formatAmount(error_m * 1e9));
  if (size < 1e-3)
    return QCoreApplication::translate("liversim::MainWindow", "≈ %1 µm")
        .arg(formatAmount(error_m * 1e6));
  return QCoreApplication::translate("liversim::MainWindow", "≈ %1 mm")
      .arg(formatAmount(error_m * 1e3));
}

QString accuracyStatusText(const RealtimeStats& stats) {
  QString text = QCoreApplication::translate("liversim::MainWindow", "%1 · error %2")
                     .arg(AccuracyPanel::integratorName(stats.integrator),
                          formatError(stats.error_estimate_m));
  if (stats.wall_s_per_simulated_s > 0.0) {
    // Both are per millisecond of simulated time: the scale of a step.
    text += QCoreApplication::translate(
                "liversim::MainWindow",
                " · %1 ms wall per ms simulated · %2 force evaluations per ms simulated")
                .arg(formatAmount(stats.wall_s_per_simulated_s),
                     formatAmount(stats.force_evaluations_per_simulated_s * 1e-3));
  }
  if (stats.stability_limited)
    text += QCoreApplication::translate("liversim::MainWindow", " · stability-limited");
  return text;
}

}  // namespace liversim
