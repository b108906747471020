// Ray-caster frame time at 512x512 on the project's own 256^3 vessel phantom (uint8,
// background 30 + noise 10, tubes 200), with the VTK benchmark's transfer function
// ("vessels" preset). Setup (phantom, Renderer::prepare) is outside the timed region.
// The side-by-side comparison with VTK is bench/render_vs_vtk.py.
#include <benchmark/benchmark.h>

#include <memory>

#include "phantom/phantom.h"
#include "render/renderer.h"

namespace {

vs::Renderer& renderer() {
  static std::unique_ptr<vs::Renderer> ren = [] {
    vs::VesselPhantomOptions po;
    po.dims = {256, 256, 256};
    po.seed = 1234;
    auto ph = vs::makeVesselPhantom(po);
    auto r = std::make_unique<vs::Renderer>(vs::AnyVolume(std::move(ph.volume)));
    r->setTransferFunction(vs::TransferFunction::preset("vessels", {0, 255, 0}));
    return r;
  }();
  return *ren;
}

void run(benchmark::State& state, vs::RenderMode mode, bool shading, bool skipping, bool perspective) {
  vs::Renderer& ren = renderer();
  vs::RenderOptions o;
  o.mode = mode;
  o.shading = shading;
  o.emptySpaceSkipping = skipping;
  ren.setOptions(o);
  ren.prepare();
  double az = 0;
  int64_t samples = 0;
  for (auto _ : state) {
    const vs::Camera cam = vs::orbitCamera(ren.geometry(), az, 20, 1.5, perspective);
    az += 36;
    auto res = ren.render(cam, 512, 512);
    samples += res.samples;
    benchmark::DoNotOptimize(res.image.pixels.data());
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["samples_per_frame"] = static_cast<double>(samples) / static_cast<double>(state.iterations());
}

void BM_Full_Shaded(benchmark::State& s) { run(s, vs::RenderMode::Full, true, true, true); }
void BM_Full_Shaded_NoSkip(benchmark::State& s) { run(s, vs::RenderMode::Full, true, false, true); }
void BM_Full_Unshaded(benchmark::State& s) { run(s, vs::RenderMode::Full, false, true, true); }
void BM_Full_Ortho(benchmark::State& s) { run(s, vs::RenderMode::Full, true, true, false); }
void BM_Mip(benchmark::State& s) { run(s, vs::RenderMode::Mip, false, true, true); }
void BM_Triplanar(benchmark::State& s) { run(s, vs::RenderMode::Triplanar, false, true, true); }

}  // namespace

BENCHMARK(BM_Full_Shaded)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Full_Shaded_NoSkip)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Full_Unshaded)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Full_Ortho)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Mip)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Triplanar)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
