// SPDX-License-Identifier: GPL-3.0-or-later
// Pruning benchmark (issues 4 and 12): the time to decide every fiber of
// concave meshes exactly (the liver, torus and Bunny, and a generated torus
// of 5,000 vertices), and the convexity check on icospheres. Prints Markdown
// tables.
//   fiberfluid_pruning [--skip-large] [--spheres-up-to K]   (K: subdivisions, default 7)
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"

namespace {

namespace geom = fiberfluid::geom;

void report_pruning(const std::string& name, const geom::Surface& s) {
  const geom::PruningResult r = geom::prune_fibers(s);
  std::cout << "| " << name << " | " << s.num_vertices() << " | " << r.mask.num_pairs() << " | "
            << r.mask.num_kept() << " | " << r.mask.num_pairs() - r.mask.num_kept() << " | "
            << r.exact_fallbacks << " | " << r.seconds << " |" << std::endl;
}

void report_convexity(int subdivisions) {
  const geom::Surface sphere = geom::icosphere(subdivisions);
  const auto start = std::chrono::steady_clock::now();
  const bool convex = geom::is_convex(sphere);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "| icosphere " << subdivisions << " | " << sphere.num_vertices() << " | "
            << sphere.num_faces() << " | " << (convex ? "yes" : "no") << " | " << seconds << " |"
            << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  bool skip_large = false;
  int largest_sphere = 7;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--skip-large") == 0) {
      skip_large = true;
      largest_sphere = 5;
    } else if (std::strcmp(argv[k], "--spheres-up-to") == 0 && k + 1 < argc) {
      largest_sphere = std::atoi(argv[++k]);
    } else {
      std::cerr << "usage: fiberfluid_pruning [--skip-large] [--spheres-up-to K]\n";
      return 2;
    }
  }
  const std::string meshes = FIBERFLUID_MESHES;
  std::cout << "| mesh | vertices | fibers in all | kept | pruned | exact fallbacks | seconds |\n"
            << "|---|---|---|---|---|---|---|" << std::endl;
  for (const char* name : {"liver.obj", "torus.obj", "Bunny.stl"})
    report_pruning(
        name,
        geom::remove_unused_vertices(geom::read_surface(meshes + "/" + name).surface).surface);
  if (!skip_large) report_pruning("torus R=2 r=0.7, 100 x 50", geom::torus(2.0, 0.7, 100, 50));

  std::cout << "\n| convexity check | vertices | faces | convex | seconds |\n"
            << "|---|---|---|---|---|" << std::endl;
  for (int subdivisions = 4; subdivisions <= largest_sphere; ++subdivisions)
    report_convexity(subdivisions);
  return 0;
}
