// SPDX-License-Identifier: GPL-3.0-or-later
// The figures an experiment's results hold, by name: what summary.json lists
// under "figures" and what "expected" may check (README, "Figures"). An
// expected figure is checked against this catalogue when the file is read,
// so a misspelt name is an error before the run, not a silent miss after it.
#pragma once

#include <string>
#include <vector>

#include "fiberfluid/model/model.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::experiment {

struct Experiment;

// The figures of one run, computed from its final state (runner.cpp): the
// names every run gives, in summary.json's order.
const std::vector<std::string>& run_figure_names();
// Those and, for a model with paddles, each paddle's final force and contacts.
std::vector<std::string> run_figure_names(const model::Model& model);

// A calibration over specimens' figures (once built): fit.cost, fit.SHARED,
// and per specimen fit.SPECIMEN.PARAMETER (its own) and
// fit.SPECIMEN.distance_sd_share (and the other distance statistics).
std::vector<std::string> calibration_figures(const Experiment& experiment);

// Whether `figure` names a figure this experiment will have; if not, why not,
// with the valid names. Benchmarks name their figures after their solvers and
// metrics: those are checked after the run only. Without `fit_figures` a
// fit's figures ("fit.*") pass: the reader checks them once the fit's
// parameters are known good (setup_fit), so that a misnamed parameter is
// the error a user sees first.
Status check_figure(const Experiment& experiment, const std::string& figure,
                    bool fit_figures = true);

}  // namespace fiberfluid::experiment
