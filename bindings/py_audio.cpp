// ambfplus/audio: DrillSound (a drill's live sound) and render_drill_sound (the same signal
// offline, from arrays of tick states).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/audio/drill_sound.h"
#include "ambfplus/audio/drill_synth.h"
#include "ambfplus/errors.h"
#include "ambfplus/haptics/drill.h"
#include "ambfplus/scene/volume.h"
#include "bindings.h"

namespace py = pybind11;

namespace ambfplus::bindings {
namespace {

using audio::DrillSound;
using audio::DrillSoundSpec;
using audio::DrillTick;
using audio::WarningTone;

// Destroys a sound with the GIL released: closing takes the world's lock, which a real-time
// loop's polling thread may hold while it waits for the GIL.
struct ReleaseGilDelete {
  void operator()(DrillSound* sound) const {
    py::gil_scoped_release release;
    delete sound;
  }
};
using SoundHolder = std::unique_ptr<DrillSound, ReleaseGilDelete>;

constexpr const char* kWarningKeys = "start, full, frequency, slow_period, fast_period";

// The default pitch of the i-th warning: a rising series of distinct tones.
double default_frequency(std::size_t i) { return 1500.0 * std::pow(2.0, 0.25 * (i % 8)); }

// A warning from a value: a start distance (m), or a mapping of kWarningKeys.
WarningTone warning_from(const std::string& name, std::uint16_t label, const py::handle& value,
                         std::size_t index) {
  WarningTone w;
  w.name = name;
  w.label = label;
  w.frequency = default_frequency(index);
  if (py::isinstance<py::dict>(value)) {
    for (const auto& [key, v] : value.cast<py::dict>()) {
      const std::string k = key.cast<std::string>();
      const double x = v.cast<double>();
      if (k == "start") {
        w.start = x;
      } else if (k == "full") {
        w.full = x;
      } else if (k == "frequency") {
        w.frequency = x;
      } else if (k == "slow_period") {
        w.slow_period = x;
      } else if (k == "fast_period") {
        w.fast_period = x;
      } else {
        throw ArgumentTypeError("warnings['" + name + "']: unknown key '" + k +
                                "' (known: " + kWarningKeys + ")");
      }
    }
  } else if (!value.is_none()) {
    w.start = value.cast<double>();
  }
  return w;
}

// The warning list of a drill's sound: None gives one per critical label of its volume (1 mm);
// a mapping names structures (label name or id) with a start distance or a mapping of settings.
std::vector<WarningTone> drill_warnings(const Drill& drill, const py::object& warnings) {
  const VolumeData& data = *drill.volume().data();
  std::vector<WarningTone> out;
  if (warnings.is_none()) {
    for (const Label& l : data.label_table().labels()) {
      if (l.critical) out.push_back(warning_from(l.name, l.id, py::none(), out.size()));
    }
    if (out.size() > static_cast<std::size_t>(audio::kMaxWarnings)) out.resize(audio::kMaxWarnings);
    return out;
  }
  for (const auto& [key, value] : warnings.cast<py::dict>()) {
    const std::vector<std::uint16_t> ids = structure_labels(data, key, "DrillSound warnings");
    const Label* label = data.label_table().find(ids.at(0));
    const std::string name = label ? label->name : std::to_string(ids.at(0));
    out.push_back(warning_from(name, ids.at(0), value, out.size()));
  }
  return out;
}

// Hardness by label id from a mapping of label names or ids.
std::vector<double> drill_hardness(const Drill& drill, const py::object& hardness) {
  std::vector<double> out;
  if (hardness.is_none()) return out;
  const VolumeData& data = *drill.volume().data();
  for (const auto& [key, value] : hardness.cast<py::dict>()) {
    for (std::uint16_t id : structure_labels(data, key, "DrillSound hardness")) {
      if (out.size() <= id) out.resize(id + 1, 1.0);
      out[id] = value.cast<double>();
    }
  }
  return out;
}

audio::AudioOutput parse_output(const std::string& output) {
  if (output == "device") return audio::AudioOutput::kDevice;
  if (output == "null") return audio::AudioOutput::kNull;
  if (output == "virtual") return audio::AudioOutput::kVirtual;
  if (output == "none") return audio::AudioOutput::kNone;
  throw ArgumentError("DrillSound: output = '" + output +
                      "', expected device, null, virtual or none");
}

py::dict stats_dict(const audio::PlayerStats& s) {
  py::dict d;
  d["pushed"] = s.pushed;
  d["rejected"] = s.rejected;
  d["played"] = s.played;
  d["dropped"] = s.dropped;
  d["held"] = s.held;
  d["callbacks"] = s.callbacks;
  d["frames"] = s.frames;
  return d;
}

using Floats = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A column of n values: the array (n values), a scalar repeated, or `fallback` for None.
std::vector<double> column(const py::object& value, py::ssize_t n, double fallback,
                           const char* name) {
  if (value.is_none()) return std::vector<double>(n, fallback);
  Floats a = Floats::ensure(value);
  if (!a) throw ArgumentTypeError(std::string("render_drill_sound: ") + name + " must be numbers");
  if (a.ndim() == 0) return std::vector<double>(n, *a.data());
  if (a.ndim() != 1 || a.shape(0) != n) {
    throw ArgumentError(std::string("render_drill_sound: ") + name + " has shape " +
                        std::to_string(a.ndim() == 1 ? a.shape(0) : -1) + ", expected (" +
                        std::to_string(n) + ",) like `on`");
  }
  return std::vector<double>(a.data(), a.data() + n);
}

py::array_t<float> render(const py::object& on, const py::object& load,
                          const py::object& removal_rate, const py::object& speed,
                          const py::object& hardness, const py::object& distances,
                          const py::object& warnings, int sample_rate, double tick_seconds,
                          std::uint64_t seed) {
  Floats on_array = Floats::ensure(on);
  if (!on_array || on_array.ndim() != 1) {
    throw ArgumentError("render_drill_sound: on must be a 1-d array (one value per tick)");
  }
  const py::ssize_t n = on_array.shape(0);
  const std::vector<double> on_v(on_array.data(), on_array.data() + n);
  const std::vector<double> load_v = column(load, n, 0.0, "load");
  const std::vector<double> rate_v = column(removal_rate, n, 0.0, "removal_rate");
  const std::vector<double> speed_v = column(speed, n, 1.0, "speed");
  const std::vector<double> hard_v = column(hardness, n, 1.0, "hardness");

  DrillSoundSpec spec;
  spec.sample_rate = sample_rate;
  spec.tick_seconds = tick_seconds;
  spec.seed = seed;
  if (!warnings.is_none()) {
    for (const auto& [key, value] : warnings.cast<py::dict>()) {
      spec.warnings.push_back(
          warning_from(py::str(key).cast<std::string>(), 0, value, spec.warnings.size()));
    }
  }
  const std::size_t structures = spec.warnings.size();
  Floats dist;
  if (structures > 0) {
    dist = Floats::ensure(distances);
    if (!dist || dist.ndim() != 2 || dist.shape(0) != n ||
        dist.shape(1) != static_cast<py::ssize_t>(structures)) {
      throw ArgumentError("render_drill_sound: distances must be an array (ticks, " +
                          std::to_string(structures) + "), one column per warning");
    }
  } else if (!distances.is_none()) {
    throw ArgumentError("render_drill_sound: distances given without warnings");
  }
  std::vector<DrillTick> ticks(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    DrillTick& t = ticks[i];
    t.on = on_v[i] > 0.5;
    t.speed = static_cast<float>(speed_v[i]);
    t.load = static_cast<float>(load_v[i]);
    t.removal_rate = static_cast<float>(rate_v[i]);
    t.hardness = static_cast<float>(hard_v[i]);
    for (std::size_t s = 0; s < structures; ++s) {
      t.distances[s] = static_cast<float>(dist.data()[i * structures + s]);
    }
  }
  std::vector<float> samples;
  {
    py::gil_scoped_release release;
    samples = audio::render_drill_sound(spec, ticks);
  }
  py::array_t<float> out(static_cast<py::ssize_t>(samples.size()));
  std::copy(samples.begin(), samples.end(), out.mutable_data());
  return out;
}

}  // namespace

void declare_audio(py::module_& m) {
  py::class_<DrillSound, SoundHolder>(
      m, "DrillSound",
      "A drill's live sound, synthesised from the burr's state (spin-up and coasting, motor "
      "pitch falling with load, cutting noise following the tissue's hardness and the removal "
      "rate, proximity beeps) and fed from the drill at every step of its world, by the "
      "haptic thread of a real-time loop. Plays through miniaudio; a machine without an "
      "audio device says so once (a warning) and carries on silent. Use as a context manager, "
      "or close().");
}

void define_audio(py::module_& m) {
  bound<DrillSound, SoundHolder>(m, "DrillSound")
      .def(py::init([](std::shared_ptr<Drill> drill, const std::string& output, bool muted,
                       bool require_device, const py::object& warnings, const py::object& hardness,
                       int sample_rate, int period_frames, int max_backlog_ticks, bool trim_backlog,
                       bool paused, double capture_seconds, std::uint64_t seed) {
             DrillSoundSpec spec;
             spec.sample_rate = sample_rate;
             spec.seed = seed;
             spec.warnings = drill_warnings(*drill, warnings);
             audio::PlayerOptions options;
             options.output = parse_output(output);
             options.muted = muted;
             options.require_device = require_device;
             options.period_frames = period_frames;
             options.max_backlog_ticks = max_backlog_ticks;
             options.trim_backlog = trim_backlog;
             options.paused = paused;
             if (!(std::isfinite(capture_seconds) && capture_seconds >= 0 &&
                   capture_seconds <= 600)) {
               throw ArgumentError("DrillSound: capture_seconds must be in 0..600");
             }
             options.capture_frames = static_cast<int>(capture_seconds * sample_rate);
             std::vector<double> hard = drill_hardness(*drill, hardness);
             py::gil_scoped_release release;
             return SoundHolder(new DrillSound(*drill, spec, options, std::move(hard)));
           }),
           py::arg("drill"), py::kw_only(), py::arg("output") = "device", py::arg("muted") = false,
           py::arg("require_device") = false, py::arg("warnings") = py::none(),
           py::arg("hardness") = py::none(), py::arg("sample_rate") = 48000,
           py::arg("period_frames") = 128, py::arg("max_backlog_ticks") = 16,
           py::arg("trim_backlog") = true, py::arg("paused") = false,
           py::arg("capture_seconds") = 0.0, py::arg("seed") = 0x5eed, py::keep_alive<1, 2>(),
           "output: 'device' (the default output: PulseAudio, ALSA or JACK), 'null' "
           "(miniaudio's null device: played at the real rate, heard by nobody; it wakes every "
           "10 ms), 'virtual' (a sound card with no hardware: asks for each period at its "
           "deadline on its own clock, heard by nobody) or 'none'. "
           "require_device: raise ResourceError instead of carrying on silent. warnings: None "
           "(a beep per critical label of the volume, from 1 mm) or {structure: start metres, "
           "or {start, full, frequency, slow_period, fast_period}}; {} for none. hardness: "
           "{structure: hardness relative to bone} (1 elsewhere). max_backlog_ticks, "
           "trim_backlog: ticks beyond what the next callback needs, and a backlog that never "
           "drains, are dropped (bounded latency). paused: open the device without starting "
           "it. capture_seconds: keep that much of what is played for take_capture().")
      .def_property_readonly(
          "drill", [](const DrillSound& s) { return handle(&s.drill()); }, "the drill it follows")
      .def_property(
          "muted", [](const DrillSound& s) { return s.player().muted(); },
          [](DrillSound& s, bool muted) { s.player().set_muted(muted); },
          "silences the output (the sound keeps running underneath)")
      .def_property(
          "paused", [](const DrillSound& s) { return s.player().paused(); },
          [](DrillSound& s, bool paused) {
            py::gil_scoped_release release;
            s.player().set_paused(paused);
          },
          "stops or restarts the device; ticks queue meanwhile")
      .def(
          "set_muted", [](DrillSound& s, bool muted) { s.player().set_muted(muted); },
          py::arg("muted"))
      .def(
          "toggle_mute",
          [](DrillSound& s) {
            s.player().set_muted(!s.player().muted());
            return s.player().muted();
          },
          "Mutes or unmutes (a launcher's mute key); returns whether it is now muted.")
      .def_property_readonly(
          "playing", [](const DrillSound& s) { return s.player().playing(); },
          "whether a device (or the null or virtual device) plays")
      .def_property_readonly(
          "device_error",
          [](const DrillSound& s) -> py::object {
            const std::string& e = s.player().device_error();
            return e.empty() ? py::object(py::none()) : py::object(py::str(e));
          },
          "why no device plays (None when one does or none was asked for)")
      .def_property_readonly(
          "backend", [](const DrillSound& s) { return s.player().backend(); },
          "the backend playing ('pulseaudio', 'alsa', 'jack', 'null', 'virtual'; '' for none)")
      .def_property_readonly(
          "period_frames", [](const DrillSound& s) { return s.player().period_frames(); },
          "frames per audio callback the device settled on")
      .def_property_readonly("sample_rate",
                             [](const DrillSound& s) { return s.player().spec().sample_rate; })
      .def_property_readonly(
          "warnings",
          [](const DrillSound& s) {
            py::list out;
            for (const WarningTone& w : s.player().spec().warnings) {
              py::dict d;
              d["name"] = w.name;
              d["label"] = w.label;
              d["start"] = w.start;
              d["full"] = w.full;
              d["frequency"] = w.frequency;
              d["slow_period"] = w.slow_period;
              d["fast_period"] = w.fast_period;
              out.append(d);
            }
            return out;
          },
          "the proximity warnings, in the order of their distances")
      .def_property_readonly(
          "stats", [](const DrillSound& s) { return stats_dict(s.player().stats()); },
          "ticks pushed, rejected (queue full), played, dropped (backlog), held (repeated while "
          "none arrived); callbacks and frames played")
      .def(
          "take_latencies",
          [](DrillSound& s) {
            const std::vector<double> v = s.player().take_latencies();
            py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
            std::copy(v.begin(), v.end(), out.mutable_data());
            return out;
          },
          "Seconds from each tick's push (the haptic step) to the moment its first sample is "
          "written into the device's buffer, for the ticks played since the last take.")
      .def(
          "take_capture",
          [](DrillSound& s) {
            const std::vector<float> v = s.player().take_capture();
            py::array_t<float> out(static_cast<py::ssize_t>(v.size()));
            std::copy(v.begin(), v.end(), out.mutable_data());
            return out;
          },
          "The samples played since the last take (capture_seconds of them at most).")
      .def(
          "close",
          [](DrillSound& s) {
            py::gil_scoped_release release;
            s.close();
          },
          "Stops feeding and closes the device; idempotent.")
      .def_property_readonly("closed", &DrillSound::closed)
      .def(
          "__enter__", [](DrillSound& s) -> DrillSound& { return s; },
          py::return_value_policy::reference)
      .def("__exit__", [](DrillSound& s, py::args) {
        py::gil_scoped_release release;
        s.close();
        return false;
      });

  m.attr("DRILL_SOUND_MAX_WARNINGS") = audio::kMaxWarnings;
  m.def("render_drill_sound", &render, py::arg("on"), py::arg("load") = py::none(),
        py::arg("removal_rate") = py::none(), py::kw_only(), py::arg("speed") = py::none(),
        py::arg("hardness") = py::none(), py::arg("distances") = py::none(),
        py::arg("warnings") = py::none(), py::arg("sample_rate") = 48000,
        py::arg("tick_seconds") = 0.001, py::arg("seed") = 0x5eed,
        "The drill sound of a tick sequence, offline: mono float32 samples at sample_rate, "
        "exactly what a DrillSound plays for the same ticks (one synthesiser). on: burr on per "
        "tick; load: N; removal_rate: m^3/s; speed: 0..1 (1); hardness: relative to bone (1); "
        "warnings: {name: start metres or {start, full, frequency, slow_period, fast_period}} "
        "with distances (ticks, len(warnings)) in metres. Deterministic.");
}

}  // namespace ambfplus::bindings
