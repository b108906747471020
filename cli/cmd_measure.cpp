// `volscissors measure TREE VOLUME [--csv sections.csv] [--json report.json] [--out tree.swc]`
// Quantification along a saved tree's centrelines (issue 24; the core is quantify/quantify.h):
// lumen cross-sections measured in the image every --step mm, per-path and per-segment
// diameters, stenosis, tortuosity, branch angles and topology. TREE is what `trace --out`
// writes (.swc, .json tree or .vtk polylines: world mm); it must lie in VOLUME (exit 1 otherwise).
// Exit status: 2 usage, 1 data/IO (unreadable files, a tree of another volume, nothing measured).
// Outputs are written together or not at all.
#include <chrono>
#include <cstdio>

#include "command.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "measure_summary.h"
#include "progress_line.h"
#include "quantify/quantify.h"
#include "quantify/report.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

const vs::QuantifyOptions kDefaults;

struct Args {
  std::string tree, volume, csv, json, out;
  std::string polarity = vs::lumenPolarityName(kDefaults.polarity);
  double stepMm = kDefaults.stepMm;
  int rays = kDefaults.rays;
};

int run(const Args& a) {
  if (a.csv.empty() && a.json.empty() && a.out.empty())
    vs::cli::note("note: no --csv, --json or --out: the summary is printed only");
  vs::QuantifyOptions o;
  o.stepMm = a.stepMm;
  o.rays = a.rays;
  o.polarity = vs::lumenPolarityFromName(a.polarity);
  const vs::Tree tree = vs::readTree(a.tree);
  vs::cli::ProgressLine progressLine("measure");
  vs::Progress& progress = progressLine.progress();
  const vs::VolumeF32 vol = vs::toFloat(vs::readVolume(a.volume, {}, nullptr, progress));
  vs::checkTreeInVolume(vol.geometry(), tree, a.tree);
  const auto t0 = std::chrono::steady_clock::now();
  const vs::TreeMeasurement m = vs::measureTree(vol, tree, o, progress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  vs::cli::clearProgressLine();
  vs::cli::printMeasurement(m, seconds);
  if (m.measuredSections() == 0)
    throw vs::DataError("no cross-section of " + a.tree + " could be measured in " + a.volume +
                        " (every one leaves the volume, meets another branch or has no lumen boundary)");
  vs::OutputSet outputs;
  if (!a.csv.empty()) outputs.writeBytes(a.csv, vs::measurementCsv(m));
  if (!a.out.empty())
    outputs.write(a.out, [&](const std::string& t) { vs::writeTree(vs::treeWithMeasuredRadii(m), t); });
  if (!a.json.empty()) {
    nlohmann::json j = {{"tree", a.tree}, {"volume", a.volume}};
    j["measure"] = vs::measurementToJson(m, o);
    j["seconds"] = {{"measure", seconds}};
    outputs.writeBytes(a.json, j.dump(1) + "\n");
  }
  outputs.commit();
  return 0;
}

const vs::cli::Registration reg{
    "measure",
    "quantify a traced tree: lumen cross-sections along the centrelines, diameters, stenosis, tortuosity, branch "
    "angles",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option("tree", a->tree, "tree from `trace --out` (.swc, .json, .vtk; world mm)")->required();
      sub.add_option("volume", a->volume, "the volume it was traced in")->required();
      sub.add_option("--csv", a->csv, "one row per cross-section of each root->tip path");
      sub.add_option("--json", a->json, "summary: sections, segments, paths, branch points");
      sub.add_option("--out", a->out, "the tree with radii from the measured cross-sections (.swc, .json, .vtk)");
      sub.add_option("--step", a->stepMm, "arc length between cross-sections (mm)")
          ->capture_default_str()
          ->check(CLI::Range(0.05, 100.0));
      sub.add_option("--rays", a->rays, "rays per cross-section")->capture_default_str()->check(CLI::Range(8, 720));
      sub.add_option("--polarity", a->polarity, "lumen: auto (from the image) | bright (CTA/MRA) | dark (airways)")
          ->capture_default_str()
          ->check(CLI::IsMember({"auto", "bright", "dark"}));
      return [a] { return run(*a); };
    }};

}  // namespace
