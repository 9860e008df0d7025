// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The names of a result folder's own files, one block per writer (each
// writer writes its files by these names and no other): the OutputWriter's
// (outputs.hpp), a fit's (fit_files.hpp), a benchmark's (benchmark_files.hpp);
// output_folder.hpp has the folder's marks. A name from an experiment file
// that makes a folder beside them (a variant's, a specimen's) is refused
// when the file is read, against the list gathered from these blocks. This
// header includes nothing of the experiment's, so the reader can use it.

#include <array>
#include <string>
#include <vector>

#include "fiberfluid/util/status.hpp"

namespace fiberfluid::experiment {

// The files an OutputWriter writes: at the top of the folder, and per run
// (at the top too, or in a variant's folder when the experiment sweeps).
namespace output_files {
inline constexpr const char* kSummary = "summary.json";
inline constexpr const char* kComparison = "comparison.csv";  // a sweep's
inline constexpr const char* kExperiment = "experiment.json";
inline constexpr const char* kResolved = "experiment.resolved.json";
inline constexpr const char* kInputSurface = "input_surface.obj";  // a program's own surface
inline constexpr const char* kFibers = "fibers.vtu";
inline constexpr const char* kFemReference = "fem_reference.obj";
inline constexpr const char* kFemReferenceVtu = "fem_reference.vtu";
inline constexpr const char* kFemReferenceSeries = "fem_reference_series.pvd";
inline constexpr const char* kFemReferenceVtk = "fem_reference_vtk";  // a folder
// Per run:
inline constexpr const char* kSteps = "steps.csv";
inline constexpr const char* kLoadDisplacement = "load_displacement.csv";
inline constexpr const char* kVertices = "vertices.csv";
inline constexpr const char* kSeries = "series.pvd";
inline constexpr const char* kVtk = "vtk";  // a folder of step_NNNN.vtu
inline constexpr const char* kFibersFinal = "fibers_final.vtu";
inline constexpr const char* kFinal = "final.obj";
// Drawn from summary.json by `--plot` (the command line's, app/cli.cpp).
inline constexpr const char* kPlot = "plot.png";
// Drawn by `predict --measured` or `--plot` (experiments/plot_prediction.py).
inline constexpr const char* kPredictionPlot = "prediction.png";
inline constexpr std::array<const char*, 19> kAll = {
    kSummary,         kComparison,      kExperiment,
    kResolved,        kInputSurface,    kFibers,
    kFemReference,    kFemReferenceVtu, kFemReferenceSeries,
    kFemReferenceVtk, kSteps,           kLoadDisplacement,
    kVertices,        kSeries,          kVtk,
    kFibersFinal,     kFinal,           kPlot,
    kPredictionPlot};
}  // namespace output_files

// The files a fit adds at the top of the output folder (and in each
// specimen's folder), and the numbered ones, K the target's index:
// fit_force_K.csv, fit_target_K.vtu, fit_target_K_scan.obj, and
// fit_other_K.csv for a target of another kind with rows (K its index among
// those: fit.json's other_targets[K]).
namespace fit_files {
inline constexpr const char* kReport = "fit.json";
inline constexpr const char* kDistances = "fit_distances.csv";
inline constexpr const char* kIterations = "fit_iterations.csv";
inline constexpr const char* kStarts = "fit_starts.csv";
inline constexpr const char* kCalibration = "calibration.json";
inline constexpr const char* kCalibrationIterations = "calibration_iterations.csv";
inline constexpr std::array<const char*, 6> kAll = {kReport, kDistances,   kIterations,
                                                    kStarts, kCalibration, kCalibrationIterations};
// A numbered name: prefix, K, suffix.
struct Numbered {
  const char* prefix;
  const char* suffix;
  std::string name(size_t k) const { return prefix + std::to_string(k) + suffix; }
};
inline constexpr Numbered kForceCurve{"fit_force_", ".csv"};
inline constexpr Numbered kTargetSurface{"fit_target_", ".vtu"};
inline constexpr Numbered kTargetScan{"fit_target_", "_scan.obj"};
inline constexpr Numbered kOtherTarget{"fit_other_", ".csv"};
// What a name must not look like (kTargetScan within the last: any .obj).
inline constexpr std::array<Numbered, 4> kNumberedForms = {
    kForceCurve, kTargetSurface, Numbered{"fit_target_", ".obj"}, kOtherTarget};
}  // namespace fit_files

// The files a benchmark adds at the top of the output folder.
namespace benchmark_files {
inline constexpr const char* kMetrics = "metrics.csv";
inline constexpr const char* kReport = "benchmark.json";
inline constexpr const char* kReferenceFinal = "reference_final.obj";
inline constexpr const char* kFiberModelFinal = "fiber_model_final.obj";
inline constexpr std::array<const char*, 4> kAll = {kMetrics, kReport, kReferenceFinal,
                                                    kFiberModelFinal};
}  // namespace benchmark_files

// The names fiberfluid writes at the top of a result folder (summary.json,
// comparison.csv, FAILED, vtk, ...): a variant or a specimen, whose folder
// sits beside them, may not take one (issue 43: refused when the file is
// read, not after the run). Also fit_force_K.csv, fit_target_K.vtu and
// fit_target_K_scan.obj for any K.
const std::vector<std::string>& reserved_result_names();
// Whether `name` is free of the reserved result names; if not, the message
// says what was expected, to follow "expected ...".
Status check_not_reserved(const std::string& name);

}  // namespace fiberfluid::experiment
