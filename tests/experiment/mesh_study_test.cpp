// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/mesh_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "../app/cli_support.hpp"
#include "../test_support.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;

TEST(MeshStudy, RichardsonFindsTheOrderAndTheLimitOfASmoothSequence) {
  // f(h) = 2 + 0.3 h^2 - 0.1 h^3 is dominated by its h^2 term: on h = 1, 1/1.5,
  // 1/2.25 and on the unequal h = 1, 0.6, 0.35 the order is near 2 and the
  // extrapolation far closer to 2 than the finest value.
  const auto f = [](double h) { return 2.0 + 0.3 * h * h - 0.01 * h * h * h; };
  for (const auto& h :
       {std::vector<double>{1.0, 1.0 / 1.5, 1.0 / 2.25}, std::vector<double>{1.0, 0.6, 0.35}}) {
    const RichardsonEstimate e = richardson(f(h[0]), f(h[1]), f(h[2]), h[0], h[1], h[2]);
    EXPECT_TRUE(e.monotone);
    EXPECT_NEAR(e.order, 2.0, 0.1);
    EXPECT_LT(std::abs(e.extrapolated - 2.0), 0.05 * std::abs(f(h[2]) - 2.0));
    EXPECT_NEAR(e.error, std::abs(e.extrapolated - f(h[2])), 1e-15);
  }
  // Exactly second order: exact.
  const RichardsonEstimate exact = richardson(1.0 + 1.0, 1.0 + 0.25, 1.0 + 0.0625, 1.0, 0.5, 0.25);
  EXPECT_NEAR(exact.order, 2.0, 1e-10);
  EXPECT_NEAR(exact.extrapolated, 1.0, 1e-12);
  // Changes of both signs have no order: the last change is the estimate.
  const RichardsonEstimate oscillating = richardson(1.0, 1.1, 1.05, 1.0, 0.5, 0.25);
  EXPECT_FALSE(oscillating.monotone);
  EXPECT_TRUE(std::isnan(oscillating.order));
  EXPECT_NEAR(oscillating.error, 0.05, 1e-12);
}

TEST(MeshStudy, RefinesWhatTheFileGivesAndNamesWhatItLacks) {
  std::string resolution;
  double factor = 0.0;
  json cylinder = {{"surface", {{"generator", "cylinder"}, {"segments", {18, 16}}}},
                   {"fem_reference", {{"E", 1000}, {"nu", 0.3}, {"size", 0.01}}}};
  json refined = refined_document(cylinder, StudiedMesh::Surface, 1.5, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["segments"], json({27, 24}));
  EXPECT_EQ(resolution, "segments [27, 24]");
  EXPECT_DOUBLE_EQ(factor, 1.5);
  refined = refined_document(cylinder, StudiedMesh::FemReference, 2.0, &resolution, &factor);
  EXPECT_DOUBLE_EQ(refined["fem_reference"]["size"].get<double>(), 0.005);
  EXPECT_EQ(refined["surface"], cylinder["surface"]);  // the surface kept
  json file = {{"surface", {{"file", "liver.obj"}, {"remesh_vertices", 1000}}}};
  refined = refined_document(file, StudiedMesh::Surface, 2.0, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["remesh_vertices"], 4000);  // vertices as h^-2
  EXPECT_DOUBLE_EQ(factor, 2.0);
  // A generator's surface remeshed: the remeshing sets the resolution, so a
  // ratio that is no power of 2 refines it and leaves the subdivisions.
  json remeshed = {
      {"surface", {{"generator", "icosphere"}, {"subdivisions", 5}, {"remesh_vertices", 600}}}};
  refined = refined_document(remeshed, StudiedMesh::Surface, 1.25, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["remesh_vertices"], 938);
  EXPECT_EQ(refined["surface"]["subdivisions"], 5);
  EXPECT_EQ(resolution, "remesh_vertices 938");
  const auto refusal = [&](const json& document, StudiedMesh mesh, double by) {
    try {
      refined_document(document, mesh, by, &resolution, &factor);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal({{"surface", {{"file", "liver.obj"}}}}, StudiedMesh::Surface, 2.0)
                .find("surface: expected the resolution"),
            std::string::npos);
  EXPECT_NE(refusal({{"surface", {{"generator", "icosphere"}, {"subdivisions", 2}}}},
                    StudiedMesh::Surface, 1.5)
                .find("surface.subdivisions: refines by factors of 2"),
            std::string::npos);
  EXPECT_NE(refusal(file, StudiedMesh::FemReference, 2.0).find("fem_reference.size"),
            std::string::npos);
}

TEST(MeshStudy, TheCommandPrintsTheOrderAndWritesTheStudy) {
  const testing::ScratchDir dir;
  std::ifstream in(testing::experiment_file("sphere.json"));
  json sphere = json::parse(in);
  sphere["surface"]["subdivisions"] = 1;
  sphere.erase("expected");
  sphere["surface"]["radius"] = 1.0;
  const auto file = dir.write("sphere.json", sphere.dump());
  const testing::Outcome outcome = testing::run_cli(
      "study mesh " + file.string() + " --ratio 2 --figure max_displacement --plot -o " +
      (dir.path() / "study").string());
  ASSERT_EQ(outcome.status, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("level 3: subdivisions 3"), std::string::npos) << outcome.output;
  std::ifstream study_file(dir.path() / "study" / "study.json");
  const json study = json::parse(study_file);
  const json& figure = study["figures"]["max_displacement"];
  ASSERT_EQ(figure["values"].size(), 3u);
  EXPECT_TRUE(figure["monotone"].get<bool>());
  EXPECT_GT(figure["observed_order"].get<double>(), 1.0);  // the paper's sphere: about 1.6
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "study" / "study.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "study" / "plot.png")) << outcome.output;
  // Run again into the same folder: replaced whole. Into a folder fiberfluid
  // did not write: refused before anything runs, the folder kept.
  const testing::Outcome again =
      testing::run_cli("study mesh " + file.string() + " --ratio 2 --figure max_displacement -o " +
                       (dir.path() / "study").string());
  EXPECT_EQ(again.status, 0) << again.output;
  dir.write("notes.txt", "mine");
  const testing::Outcome foreign =
      testing::run_cli("study mesh " + file.string() + " --ratio 2 -o " + dir.path().string());
  EXPECT_NE(foreign.status, 0);
  EXPECT_EQ(foreign.output.find("level 1 of 3"), std::string::npos) << foreign.output;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "notes.txt"));
  // A file it cannot refine: named, exit status of bad input.
  sphere["surface"].erase("subdivisions");
  const auto bare = dir.write("bare.json", sphere.dump());
  const testing::Outcome refused = testing::run_cli("study mesh " + bare.string() + " --ratio 2");
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.output.find("surface: expected the resolution"), std::string::npos)
      << refused.output;
}

// fit.mesh_check: the paper's sphere fitted exactly on its own mesh
// (subdivisions 2) and again on the next coarser (1): the coarse sphere needs
// other parameters, and the shift, far beyond the exact fit's interval, is
// reported and warned of.
// Issue 44, "fibers whose parameters converge": the soft cylinder under its
// weight at fixed parameters (central fibers within 5 cm, the clamp's mirror
// layer, 4 Newton steps) on segments [18, 16], [23, 20], [28, 25]. With the
// paper's count and a constant influence its largest displacement jumps
// (0.1344, 0.1239, 0.1282 m: the cap's rings and the horizon's edge take in
// vertices unevenly as the mesh changes); with the central fibers' defaults
// (the area count and the conical influence) it falls monotonically by
// shrinking steps (0.14443, 0.14350, 0.14340 m; at [35, 31] 0.14321).
TEST(MeshStudy, CentralFibersByDefaultConvergeMonotonicallyWithTheMesh) {
  testing::ScratchDir dir;
  nlohmann::json doc = nlohmann::json::parse(R"({
    "name": "cylinder_study",
    "surface": {"generator": "cylinder", "radius": 0.02, "length": 0.18, "segments": [18, 16]},
    "material": {"Y": 100000, "gamma": 0},
    "fibers": {"kinematics": "central", "horizon": 0.05},
    "supports": [{"label": "clamp", "where": "x <= 0", "layer": "mirror"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81], "density": 1000,
               "integration": "exact"}],
    "stepping": {"scheme": "newton", "steps": 4}
  })");
  MeshStudySpec spec;
  spec.ratio = 1.25;
  spec.figures = {"max_displacement"};
  const auto study = [&](const nlohmann::json& d) {
    const MeshStudy s = run_mesh_study(dir.write("study.json", d.dump()), spec);
    return s.figures.at(0).values;
  };
  const std::vector<double> converging = study(doc);
  ASSERT_EQ(converging.size(), 3u);
  EXPECT_NEAR(converging[0], 0.14443, 2e-5);
  EXPECT_GT(converging[0], converging[1]);
  EXPECT_GT(converging[1], converging[2]);
  EXPECT_LT(converging[1] - converging[2], converging[0] - converging[1]);
  EXPECT_LT((converging[1] - converging[2]) / converging[2], 0.003);

  doc["fibers"]["connection_count"] = "symmetric";
  doc["fibers"]["influence"] = "constant";
  const std::vector<double> paper = study(doc);
  EXPECT_NEAR(paper[0], 0.13439, 2e-5);
  EXPECT_LT(paper[1], paper[0]);  // down by 8%, then up by 3%: not monotone
  EXPECT_GT(paper[2], paper[1]);
}

// Issue 44's sphere under gravity (experiments/dome_mesh_study.json): the
// octahedron's half sphere hanging from its wall, whose edge is split and
// whose counts mix by their mean. Subdivisions 2 to 5: 1.3558, 1.4321,
// 1.4725, 1.4843 mm, monotone, order 1.77, the two finest 0.80% apart. With
// the edge held, the area count and the exact load (the study before the
// split) the order was 1.16 and the two finest 3.0% apart (docs/model.md).
TEST(MeshStudy, TheSphereUnderGravityConvergesWithItsEdgeSplit) {
  MeshStudySpec spec;
  spec.levels = 4;
  spec.ratio = 2.0;
  spec.figures = {"max_displacement"};
  const MeshStudy s = run_mesh_study(testing::experiment_file("dome_mesh_study.json"), spec);
  const std::vector<double>& v = s.figures.at(0).values;
  ASSERT_EQ(v.size(), 4u);
  const std::vector<double> expected = {1.35577e-3, 1.43211e-3, 1.47248e-3, 1.48435e-3};
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-8) << k;
  for (size_t k = 1; k < v.size(); ++k) EXPECT_GT(v[k], v[k - 1]);
  EXPECT_LT((v[3] - v[2]) / v[3], 0.01);
  const RichardsonEstimate finest = richardson(v[1], v[2], v[3], 0.5, 0.25, 0.125);
  EXPECT_TRUE(finest.monotone);
  EXPECT_GT(finest.order, 1.5);
}

TEST(FitMeshCheck, AFitReportsHowFarItsParametersMoveOnACoarserMesh) {
  const testing::ScratchDir dir;
  std::ifstream in(testing::experiment_file("fit_sphere.json"));
  json fit = json::parse(in);
  fit["fit"]["mesh_check"] = "coarser";
  fit.erase("expected");
  fit["fit"]["targets"][0]["file"] = (testing::experiment_file("fit_sphere.json").parent_path() /
                                      fit["fit"]["targets"][0]["file"].get<std::string>())
                                         .string();
  const auto file = dir.write("fit.json", fit.dump());
  const testing::Outcome outcome =
      testing::run_cli("fit " + file.string() + " -q -o " + (dir.path() / "out").string());
  ASSERT_EQ(outcome.status, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("mesh check (subdivisions 1"), std::string::npos) << outcome.output;
  EXPECT_NE(outcome.output.find("warning: the mesh moves gamma further than its statistical"),
            std::string::npos)
      << outcome.output;
  std::ifstream summary_file(dir.path() / "out" / "summary.json");
  const json figures = json::parse(summary_file)["figures"];
  EXPECT_NEAR(figures["fit.gamma"].get<double>(), 3000.0, 1e-3);  // the fit itself: exact
  const double shift = figures["fit.mesh_shift.gamma"].get<double>();
  EXPECT_GT(std::abs(shift), 10.0);
  EXPECT_NEAR(figures["fit.mesh_check.gamma"].get<double>(),
              figures["fit.gamma"].get<double>() + shift, 1e-9);
}

}  // namespace
}  // namespace fiberfluid::experiment
