// ambfplus_bench: the C++ halves of tests/benchmarks/run.py's comparisons, a test-only extension
// module built beside the tests (never installed, never part of ambfplus._core). It takes the
// objects of ambfplus._core (pybind11 shares the types between modules) and works on them
// through libambfplus, which the loader shares with _core by its soname: import ambfplus first.

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <time.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <thread>
#include <vector>

#include "ambfplus/audio/drill_sound.h"
#include "ambfplus/capture/capture.h"
#include "ambfplus/capture/frame.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/haptics/voxel_collider.h"
#include "ambfplus/scene/camera.h"
#include "ambfplus/scene/volume.h"

namespace py = pybind11;
using ambfplus::Camera;
using ambfplus::CaptureBuffers;
using ambfplus::Drill;
using ambfplus::Frame;
using ambfplus::SweepHit;
using ambfplus::VoxelCollider;
using Vec3 = Eigen::Vector3d;

namespace {

// CPU seconds of the whole process (all threads, the rasteriser's included).
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

PYBIND11_MODULE(ambfplus_bench, m) {
  m.doc() = "benchmark baselines in C++ (tests/benchmarks/run.py; not part of ambfplus)";
  py::module_::import("ambfplus._core");  // the classes of the arguments

  // The baseline of the capture benchmark: the same draw and readback, in C++, into buffers
  // allocated once, with no Python in the loop.
  m.def(
      "bare_capture",
      [](Camera& camera, int iterations) {
        std::vector<std::uint8_t> rgb(static_cast<std::size_t>(camera.width()) * camera.height() *
                                      3);
        std::vector<float> depth(static_cast<std::size_t>(camera.width()) * camera.height());
        std::vector<std::uint16_t> label(depth.size());
        Frame frame;
        double wall = 0, cpu = 0;
        {
          py::gil_scoped_release release;
          const CaptureBuffers buffers{rgb.data(), depth.data(), label.data()};
          ambfplus::capture_into(camera, buffers, frame);  // warm-up: context, program, buffers
          const auto t0 = std::chrono::steady_clock::now();
          const double c0 = process_cpu_seconds();
          for (int i = 0; i < iterations; ++i) ambfplus::capture_into(camera, buffers, frame);
          cpu = process_cpu_seconds() - c0;
          wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        py::dict d;
        d["wall_seconds"] = wall / iterations;
        d["cpu_seconds"] = cpu / iterations;
        return d;
      },
      py::arg("camera"), py::arg("iterations"));

  m.def(
      "removal",
      [](Drill& d, int count) {
        // Removes up to `count` voxels nearest the burr through the collider (bitmaps, volume,
        // edit log), as a drilling step does, and times it.
        auto& c = const_cast<VoxelCollider&>(d.collider());
        const Eigen::Isometry3d vfw = d.volume().pose().inverse();
        const Vec3 tip = vfw * d.cursor_proxy(0);
        std::vector<std::array<int, 3>> voxels = c.solid_within(tip, d.burr_radius() * 1.5);
        if (static_cast<int>(voxels.size()) > count) voxels.resize(count);
        double seconds = 0;
        {
          py::gil_scoped_release release;
          const auto t0 = std::chrono::steady_clock::now();
          c.remove(voxels);
          seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        py::dict out;
        out["voxels"] = voxels.size();
        out["seconds"] = seconds;
        return out;
      },
      py::arg("drill"), py::arg("count"));

  m.def(
      "collision",
      [](Drill& d, int cursor, int iterations) {
        // The cursor's last sweep (proxy to goal) as a gather and as a full-cube scan.
        const VoxelCollider& c = d.collider();
        const Eigen::Isometry3d vfw = d.volume().pose().inverse();
        const Vec3 a = vfw * d.cursor_proxy(cursor), b = vfw * d.cursor_goal(cursor);
        const double r = d.cursor_radius(cursor);
        SweepHit gather, full;
        double gather_s = 0, full_s = 0;
        std::int64_t gather_n = 0, full_n = 0;
        {
          py::gil_scoped_release release;
          auto& counter = const_cast<VoxelCollider&>(c);
          counter.reset_counters();
          auto t0 = std::chrono::steady_clock::now();
          for (int i = 0; i < iterations; ++i) gather = c.sweep(a, b, r);
          gather_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                     iterations;
          gather_n = c.voxels_tested() / iterations;
          counter.reset_counters();
          t0 = std::chrono::steady_clock::now();
          for (int i = 0; i < iterations; ++i) full = c.sweep_full_cube(a, b, r);
          full_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                   iterations;
          full_n = c.voxels_tested() / iterations;
        }
        py::dict out;
        out["gather_seconds"] = gather_s;
        out["full_cube_seconds"] = full_s;
        out["gather_voxels"] = gather_n;
        out["full_cube_voxels"] = full_n;
        out["hit"] = gather.hit;
        out["same_hit"] = gather.hit == full.hit && std::abs(gather.t - full.t) < 1e-9;
        return out;
      },
      py::arg("drill"), py::arg("cursor") = 0, py::arg("iterations") = 20);

  // The live drill sound's own latency, with no audio library in the way: a producer pushing a
  // tick every millisecond and a consumer running the audio thread's fill() every period, both
  // on absolute deadlines, as a haptic loop and a device of that period would.
  m.def(
      "drill_sound_paced_latency",
      [](double seconds, int period_frames) {
        namespace audio = ambfplus::audio;
        audio::DrillSoundSpec spec;
        audio::PlayerOptions options;
        options.output = audio::AudioOutput::kNone;
        audio::DrillSoundPlayer player(spec, options);
        std::vector<double> latencies;
        {
          py::gil_scoped_release release;
          using Clock = std::chrono::steady_clock;
          std::atomic<bool> stop{false};
          const auto period = std::chrono::duration_cast<Clock::duration>(
              std::chrono::duration<double>(period_frames / double(spec.sample_rate)));
          std::thread device([&] {
            std::vector<float> buffer(period_frames);
            auto next = Clock::now();
            while (!stop) {
              next += period;
              std::this_thread::sleep_until(next);
              player.fill(buffer.data(), static_cast<std::uint32_t>(period_frames));
            }
          });
          audio::DrillTick tick;
          tick.on = true;
          tick.load = 1.0f;
          tick.removal_rate = 20e-9f;
          auto next = Clock::now();
          const auto ticks = static_cast<int>(seconds * 1000);
          for (int i = 0; i < ticks; ++i) {
            next += std::chrono::milliseconds(1);
            std::this_thread::sleep_until(next);
            player.push(tick);
            if (i % 1000 == 999) {
              for (double v : player.take_latencies()) latencies.push_back(v);
            }
          }
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
          stop = true;
          device.join();
          for (double v : player.take_latencies()) latencies.push_back(v);
        }
        return latencies;
      },
      py::arg("seconds"), py::arg("period_frames") = 128,
      "Seconds from each tick's push to its first sample's write, with a paced consumer.");

  m.def(
      "fixture_queries",
      [](const Drill& d, const std::vector<Vec3>& points, int rounds) {
        // Each query timed alone: the fixtures' push on the burr centred at a point (every
        // fixture's field sampled), as a tick evaluates it for its tip cursor.
        std::vector<double> seconds;
        seconds.reserve(points.size() * rounds);
        Vec3 sink = Vec3::Zero();
        {
          py::gil_scoped_release release;
          for (int r = 0; r < rounds; ++r) {
            for (const Vec3& p : points) {
              const auto t0 = std::chrono::steady_clock::now();
              sink += d.fixture_push(p);
              const auto t1 = std::chrono::steady_clock::now();
              seconds.push_back(std::chrono::duration<double>(t1 - t0).count());
            }
          }
        }
        py::dict out;
        out["seconds"] = seconds;
        out["checksum"] = sink.norm();
        return out;
      },
      py::arg("drill"), py::arg("points"), py::arg("rounds") = 1);
}
