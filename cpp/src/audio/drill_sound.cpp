#include "ambfplus/audio/drill_sound.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>

#include <dlfcn.h>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "miniaudio_config.h"
#include "spsc_ring.h"

namespace ambfplus::audio {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Callbacks over which the standing backlog is measured (about 0.17 s at 128 frames, 48 kHz).
constexpr int kWindow = 64;

// A machine without audio says so once per process, however many players it makes.
std::atomic<bool> g_said_no_device{false};

// ALSA prints every failed probe of a machine without a card to stderr; the player says why
// once instead. libasound is the one miniaudio loaded, if it did.
void alsa_silent(const char*, int, const char*, int, const char*, ...) {}
void quieten_alsa() {
  void* alsa = dlopen("libasound.so.2", RTLD_NOW | RTLD_NOLOAD);
  if (alsa == nullptr) return;
  using Handler = void (*)(const char*, int, const char*, int, const char*, ...);
  using SetHandler = int (*)(Handler);
  if (auto set = reinterpret_cast<SetHandler>(dlsym(alsa, "snd_lib_error_set_handler"))) {
    set(&alsa_silent);
  }
  dlclose(alsa);
}

void add(std::atomic<std::int64_t>& counter, std::int64_t n = 1) {
  counter.fetch_add(n, std::memory_order_relaxed);
}

// The virtual output, through miniaudio's custom backend: a playback device with no hardware.
// miniaudio's audio thread asks the player for a period and writes it here; the write returns
// when that period starts to play on the device's own clock (its start plus the frames written
// so far), as a card's interrupt paces its driver. So the player is called once per period on
// absolute deadlines, one period ahead of what plays. (miniaudio's null device instead wakes
// every 10 ms and then asks for every period that fell due at once.)
struct VirtualClock {
  std::chrono::steady_clock::time_point start;
  std::uint64_t frames = 0;
};

VirtualClock& clock_of(ma_device* device) {
  return *static_cast<VirtualClock*>(device->pContext->pUserData);
}

void describe_virtual(ma_device_info* info) {
  *info = ma_device_info{};
  std::snprintf(info->name, sizeof(info->name), "%s", "ambfplus virtual output");
  info->isDefault = MA_TRUE;
  info->nativeDataFormatCount = 1;
  info->nativeDataFormats[0].format = ma_format_f32;  // channels and rate: any
}

ma_result virtual_enumerate(ma_context* context, ma_enum_devices_callback_proc callback,
                            void* user) {
  ma_device_info info;
  describe_virtual(&info);
  callback(context, ma_device_type_playback, &info, user);
  return MA_SUCCESS;
}

ma_result virtual_device_info(ma_context*, ma_device_type type, const ma_device_id*,
                              ma_device_info* info) {
  if (type != ma_device_type_playback) return MA_DEVICE_TYPE_NOT_SUPPORTED;
  describe_virtual(info);
  return MA_SUCCESS;
}

ma_result virtual_device_init(ma_device*, const ma_device_config* config,
                              ma_device_descriptor* playback, ma_device_descriptor*) {
  if (config->deviceType != ma_device_type_playback) return MA_DEVICE_TYPE_NOT_SUPPORTED;
  if (playback->format == ma_format_unknown) playback->format = ma_format_f32;
  if (playback->channels == 0) playback->channels = 1;
  if (playback->sampleRate == 0) playback->sampleRate = 48000;
  if (playback->channelMap[0] == MA_CHANNEL_NONE) {
    ma_channel_map_init_standard(ma_standard_channel_map_default, playback->channelMap,
                                 MA_MAX_CHANNELS, playback->channels);
  }
  playback->periodSizeInFrames = ma_calculate_buffer_size_in_frames_from_descriptor(
      playback, playback->sampleRate, config->performanceProfile);
  playback->periodCount = 2;
  return MA_SUCCESS;
}

ma_result virtual_start(ma_device* device) {
  clock_of(device) = VirtualClock{std::chrono::steady_clock::now(), 0};
  return MA_SUCCESS;
}

ma_result virtual_write(ma_device* device, const void*, ma_uint32 frames, ma_uint32* written) {
  VirtualClock& clock = clock_of(device);
  const double rate = device->playback.internalSampleRate;
  std::this_thread::sleep_until(
      clock.start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(static_cast<double>(clock.frames) / rate)));
  clock.frames += frames;
  *written = frames;
  return MA_SUCCESS;
}

ma_result virtual_nothing(ma_context*) { return MA_SUCCESS; }
ma_result virtual_device_nothing(ma_device*) { return MA_SUCCESS; }

ma_result virtual_context_init(ma_context*, const ma_context_config*,
                               ma_backend_callbacks* callbacks) {
  callbacks->onContextInit = virtual_context_init;
  callbacks->onContextUninit = virtual_nothing;
  callbacks->onContextEnumerateDevices = virtual_enumerate;
  callbacks->onContextGetDeviceInfo = virtual_device_info;
  callbacks->onDeviceInit = virtual_device_init;
  callbacks->onDeviceUninit = virtual_device_nothing;
  callbacks->onDeviceStart = virtual_start;
  callbacks->onDeviceStop = virtual_device_nothing;
  callbacks->onDeviceWrite = virtual_write;
  return MA_SUCCESS;
}

}  // namespace

struct DrillSoundPlayer::Impl {
  Impl(const DrillSoundSpec& s, const PlayerOptions& o)
      : spec(s),
        options(o),
        synth(s),
        ticks(static_cast<std::size_t>(o.queue_ticks)),
        latencies(8192),
        capture(static_cast<std::size_t>(std::max(o.capture_frames, 2))),
        pending(static_cast<std::size_t>(std::ceil(s.frames_per_tick())) + 1) {}

  DrillSoundSpec spec;
  PlayerOptions options;
  DrillSynth synth;  // the audio thread's alone
  SpscRing<DrillTick> ticks;
  SpscRing<double> latencies;
  SpscRing<float> capture;
  // The frames of the tick being played (rendered whole, handed out as the device asks).
  std::vector<float> pending;
  int pending_count = 0, pending_at = 0;
  DrillTick last;        // repeated while no tick arrives
  bool started = false;  // a tick has been played
  std::atomic<bool> paused{false};
  // The fewest ticks left waiting after a callback, over the last kWindow callbacks: a backlog
  // that never drains (the queue's standing delay) is dropped once the window closes.
  std::size_t window_min = SIZE_MAX;
  int window_callbacks = 0;
  std::atomic<bool> muted{false};
  std::atomic<bool> open{false};
  std::atomic<std::int64_t> pushed{0}, rejected{0}, played{0}, dropped{0}, held{0}, callbacks{0},
      frames{0};
  std::string device_error, backend;
  int period = 0;
  ma_context context{};
  ma_device device{};
  bool have_context = false, have_device = false;
  std::mutex close_mutex;
  VirtualClock virtual_clock;  // the virtual output's (the context's user data)

  void open_output();
  void close();
};

namespace {

void data_callback(ma_device* device, void* output, const void*, ma_uint32 frames) {
  auto* player = static_cast<DrillSoundPlayer*>(device->pUserData);
  player->fill(static_cast<float*>(output), frames);
}

}  // namespace

void DrillSoundPlayer::Impl::open_output() {
  if (options.output == AudioOutput::kNone) return;
  // The null and virtual outputs are heard by nobody: no system device is tried.
  const bool null = options.output == AudioOutput::kNull || options.output == AudioOutput::kVirtual;
  const ma_backend real[] = {ma_backend_pulseaudio, ma_backend_alsa, ma_backend_jack};
  const ma_backend none[] = {ma_backend_null};
  const ma_backend custom[] = {ma_backend_custom};
  std::string failure;
  ma_context_config context_config = ma_context_config_init();
  ma_result result;
  if (options.output == AudioOutput::kVirtual) {
    context_config.pUserData = &virtual_clock;
    context_config.custom.onContextInit = virtual_context_init;
    result = ma_context_init(custom, 1, &context_config, &context);
  } else {
    result = null ? ma_context_init(none, 1, &context_config, &context)
                  : ma_context_init(real, 3, &context_config, &context);
  }
  if (result != MA_SUCCESS) {
    failure = std::string("no audio backend opened (") + ma_result_description(result) + ")";
  } else {
    have_context = true;
    if (!null) quieten_alsa();
    ma_device_config config = ma_device_config_init(ma_device_type_playback);
    config.playback.format = ma_format_f32;
    config.playback.channels = 1;
    config.sampleRate = static_cast<ma_uint32>(spec.sample_rate);
    config.periodSizeInFrames = static_cast<ma_uint32>(options.period_frames);
    config.performanceProfile = ma_performance_profile_low_latency;
    config.noClip = MA_TRUE;  // the synthesiser clips
    config.dataCallback = data_callback;
    config.pUserData = nullptr;  // set by the player before the device starts
    result = ma_device_init(&context, &config, &device);
    if (result != MA_SUCCESS) {
      failure =
          std::string("no audio output device opened (") + ma_result_description(result) + ")";
    } else {
      have_device = true;
    }
  }
  if (failure.empty()) return;
  close();
  device_error = failure + (null ? "" : " on PulseAudio, ALSA or JACK");
  if (options.require_device) throw ResourceError("DrillSoundPlayer: " + device_error);
  if (!g_said_no_device.exchange(true)) {
    log(LogLevel::kWarning, "drill sound: " + device_error + "; carrying on silent");
  }
}

void DrillSoundPlayer::Impl::close() {
  std::lock_guard<std::mutex> lock(close_mutex);
  open = false;
  if (have_device) ma_device_uninit(&device);
  if (have_context) ma_context_uninit(&context);
  have_device = have_context = false;
}

DrillSoundPlayer::DrillSoundPlayer(const DrillSoundSpec& spec, const PlayerOptions& options) {
  spec.validate();
  if (options.period_frames < 16 || options.period_frames > 16384) {
    throw ArgumentError("DrillSoundPlayer: period_frames = " +
                        std::to_string(options.period_frames) + ", expected 16..16384");
  }
  if (options.max_backlog_ticks < 0 || options.queue_ticks < 2 || options.capture_frames < 0) {
    throw ArgumentError(
        "DrillSoundPlayer: max_backlog_ticks >= 0, queue_ticks >= 2 and capture_frames >= 0 "
        "expected");
  }
  impl_ = std::make_unique<Impl>(spec, options);
  impl_->muted = options.muted;
  impl_->open_output();
  if (impl_->have_device) {
    impl_->device.pUserData = this;
    impl_->period = static_cast<int>(impl_->device.playback.internalPeriodSizeInFrames);
    impl_->backend = options.output == AudioOutput::kVirtual
                         ? "virtual"
                         : ma_get_backend_name(impl_->context.backend);
    impl_->open = true;
    impl_->paused = options.paused;
    const ma_result result = options.paused ? MA_SUCCESS : ma_device_start(&impl_->device);
    if (result != MA_SUCCESS) {
      impl_->close();
      impl_->backend.clear();
      impl_->device_error =
          std::string("the audio device did not start (") + ma_result_description(result) + ")";
      if (options.require_device) throw ResourceError("DrillSoundPlayer: " + impl_->device_error);
      log(LogLevel::kWarning, "drill sound: " + impl_->device_error + "; carrying on silent");
    }
  } else if (options.output == AudioOutput::kNone) {
    impl_->open = true;  // accepts ticks for fill() by hand
  }
}

DrillSoundPlayer::~DrillSoundPlayer() { impl_->close(); }

const DrillSoundSpec& DrillSoundPlayer::spec() const { return impl_->spec; }
const PlayerOptions& DrillSoundPlayer::options() const { return impl_->options; }
void DrillSoundPlayer::set_paused(bool paused) {
  Impl& p = *impl_;
  std::lock_guard<std::mutex> lock(p.close_mutex);
  if (!p.have_device || p.paused == paused) return;
  const ma_result result = paused ? ma_device_stop(&p.device) : ma_device_start(&p.device);
  if (result != MA_SUCCESS) {
    throw ResourceError(std::string("DrillSoundPlayer: the audio device did not ") +
                        (paused ? "stop" : "start") + " (" + ma_result_description(result) + ")");
  }
  p.paused = paused;
}
bool DrillSoundPlayer::paused() const { return impl_->paused; }
void DrillSoundPlayer::set_muted(bool muted) { impl_->muted = muted; }
bool DrillSoundPlayer::muted() const { return impl_->muted; }
bool DrillSoundPlayer::playing() const { return impl_->open && impl_->have_device; }
const std::string& DrillSoundPlayer::device_error() const { return impl_->device_error; }
const std::string& DrillSoundPlayer::backend() const { return impl_->backend; }
int DrillSoundPlayer::period_frames() const { return impl_->period; }
void DrillSoundPlayer::close() { impl_->close(); }

bool DrillSoundPlayer::push(DrillTick tick) {
  if (!impl_->open.load(std::memory_order_relaxed)) return false;
  tick.pushed_ns = now_ns();
  if (!impl_->ticks.push(tick)) {
    add(impl_->rejected);
    return false;
  }
  add(impl_->pushed);
  return true;
}

void DrillSoundPlayer::fill(float* out, std::uint32_t frames) {
  Impl& p = *impl_;
  add(p.callbacks);
  // Ticks beyond what this callback needs and the allowed backlog are the oldest: dropped.
  const double left = static_cast<double>(frames) - (p.pending_count - p.pending_at);
  const auto needed =
      static_cast<std::size_t>(std::max(0.0, std::ceil(left / p.spec.frames_per_tick())));
  const std::size_t waiting = p.ticks.size();
  const std::size_t keep = needed + static_cast<std::size_t>(p.options.max_backlog_ticks);
  DrillTick tick;
  for (std::size_t i = keep; i < waiting; ++i) {
    if (p.ticks.pop(tick)) add(p.dropped);
  }
  std::uint32_t n = 0;
  // Silence until the first tick, the synthesiser untouched: it starts where an offline
  // render starts.
  if (!p.started) {
    if (p.ticks.size() == 0) {
      std::fill(out, out + frames, 0.0f);
      n = frames;
    }
    p.started = n == 0;
  }
  while (n < frames) {
    if (p.pending_at < p.pending_count) {
      const std::uint32_t take = std::min<std::uint32_t>(
          frames - n, static_cast<std::uint32_t>(p.pending_count - p.pending_at));
      std::memcpy(out + n, p.pending.data() + p.pending_at, take * sizeof(float));
      n += take;
      p.pending_at += static_cast<int>(take);
      continue;
    }
    if (p.ticks.pop(tick)) {
      add(p.played);
      p.last = tick;
      // Its first sample goes into the device's buffer now.
      p.latencies.push((now_ns() - tick.pushed_ns) * 1e-9);  // dropped when nobody takes them
    } else {
      add(p.held);
      tick = p.last;
    }
    p.pending_count = p.synth.render_tick(tick, p.pending.data());
    p.pending_at = 0;
  }
  // A standing backlog is latency for nothing: drop it (a tick short later is repeated).
  p.window_min = std::min(p.window_min, p.ticks.size());
  if (++p.window_callbacks == kWindow && p.options.trim_backlog) {
    for (std::size_t i = 0; i < p.window_min; ++i) {
      if (p.ticks.pop(tick)) add(p.dropped);
    }
  }
  if (p.window_callbacks == kWindow) {
    p.window_min = SIZE_MAX;
    p.window_callbacks = 0;
  }
  if (p.muted.load(std::memory_order_relaxed)) std::fill(out, out + frames, 0.0f);
  if (p.options.capture_frames > 0) {
    for (std::uint32_t i = 0; i < frames; ++i) p.capture.push(out[i]);
  }
  add(p.frames, frames);
}

std::vector<double> DrillSoundPlayer::take_latencies() {
  std::vector<double> out;
  double v;
  while (impl_->latencies.pop(v)) out.push_back(v);
  return out;
}

std::vector<float> DrillSoundPlayer::take_capture() {
  std::vector<float> out;
  float v;
  while (impl_->capture.pop(v)) out.push_back(v);
  return out;
}

PlayerStats DrillSoundPlayer::stats() const {
  const Impl& p = *impl_;
  PlayerStats s;
  s.pushed = p.pushed;
  s.rejected = p.rejected;
  s.played = p.played;
  s.dropped = p.dropped;
  s.held = p.held;
  s.callbacks = p.callbacks;
  s.frames = p.frames;
  return s;
}

}  // namespace ambfplus::audio
