"""The drill sound (issue 30, "Sound behaves"): measured on offline renders of scripted sessions
and of synthetic tick sequences, so no sound card is needed. The pitch is found by FFT peak, the
cutting band's energy by summing the spectrum above the motor's harmonics, beeps by their
envelope; each claim is checked so that a synthesiser without the behaviour fails."""

from __future__ import annotations

import logging
import time
import wave

import numpy as np
import pytest

import ambfplus
from ambfplus import DrillSound, render_drill_sound
from ambfplus.audio import drill_ticks, render_session, render_wav
from ambfplus.recording import Recorder, open_recording
from ambfplus.scenes import drilling_phantom
from ambfplus.training import TrainingRegion, drill_phantom, expert_like, novice_like

RATE = 48000
WINDOW = 4800  # 100 ms
PROTECT = [("facial nerve", "Facial_Nerve", 0.001)]


def ranks(values) -> np.ndarray:
    return np.argsort(np.argsort(np.asarray(values, dtype=float))).astype(float)


def spearman(a, b) -> float:
    return float(np.corrcoef(ranks(a), ranks(b))[0, 1])


def spectrum(segment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    power = np.abs(np.fft.rfft(segment * np.hanning(len(segment)))) ** 2
    return np.fft.rfftfreq(len(segment), 1 / RATE), power


def fundamental(segment: np.ndarray) -> float:
    """The strongest peak between 150 and 800 Hz (the motor's range), interpolated."""
    freqs, power = spectrum(segment)
    i = int(np.argmax(np.where((freqs > 150) & (freqs < 800), power, 0)))
    a, b, c = np.log(power[i - 1 : i + 2])
    return float((i + 0.5 * (a - c) / (a - 2 * b + c)) * freqs[1])


def cutting_energy(segment: np.ndarray) -> float:
    """Energy of the band above the motor's 4th harmonic (2.6 to 6 kHz)."""
    freqs, power = spectrum(segment)
    return float(power[(freqs > 2600) & (freqs < 6000)].sum())


@pytest.fixture(
    scope="module", params=[(novice_like, 3), (expert_like, 7)], ids=["novice", "expert"]
)
def session(request):
    make, seed = request.param
    # A 12 mm square over the origin, the cortex and the canal's rim, where cutting is steady.
    s = drill_phantom(make, seed, 8.0, PROTECT, resolution=64, region=TrainingRegion())
    size = s.drill.volume.data.voxel_size
    ticks = drill_ticks(s.steps, s.removed, s.drill.name, size)
    samples = render_session(s.steps, s.removed, s.drill.name, size)
    return s, ticks, samples


def settled_windows(ticks):
    """100 ms windows with the burr on since 150 ms before (the motor has spun up)."""
    on = ticks["on"]
    for k in range(len(on) // 100):
        if on[max(0, k * 100 - 150) : (k + 1) * 100].all():
            yield k


def ticks_of(n, **columns) -> dict:
    out = {"on": np.ones(n), "load": np.zeros(n), "removal_rate": np.zeros(n)}
    out.update({k: np.broadcast_to(np.asarray(v, float), (n,)).copy() for k, v in columns.items()})
    return out


# -- the motor ---------------------------------------------------------------------------------


def test_the_fundamental_falls_with_load_in_a_scripted_session(session):
    _, ticks, samples = session
    f0, load = [], []
    for k in settled_windows(ticks):
        f0.append(fundamental(samples[k * WINDOW : (k + 1) * WINDOW]))
        load.append(ticks["load"][k * 100 - 60 : (k + 1) * 100].mean())  # the motor lags
    assert len(f0) >= 30
    assert max(f0) - min(f0) > 30, "the pitch hardly moves"
    assert spearman(f0, load) < -0.8


def test_the_fundamental_falls_with_each_step_of_load():
    loads = [0.0, 0.5, 1.0, 2.0, 4.0]
    pitches = []
    for load in loads:
        samples = render_drill_sound(**ticks_of(1000, load=load))
        pitches.append(fundamental(samples[-WINDOW:]))
    assert pitches[0] == pytest.approx(600, abs=3)  # the motor's frequency, unloaded
    assert all(a > b + 5 for a, b in zip(pitches, pitches[1:])), pitches


def test_the_motor_spins_up_and_coasts_down():
    on = np.r_[np.ones(600), np.zeros(600)]
    samples = render_drill_sound(on)
    level = [np.sqrt(np.mean(samples[i : i + 2400] ** 2)) for i in range(0, len(samples), 2400)]
    # Rising for the first 100 ms, falling after the switch-off, zero once stopped.
    assert level[0] < level[1] < level[2] and level[12] > level[13] > level[14]
    assert level[-1] == 0.0


# -- cutting -----------------------------------------------------------------------------------


def test_the_cutting_band_follows_the_removal_rate_in_a_scripted_session(session):
    _, ticks, samples = session
    energy, rate = [], []
    for k in settled_windows(ticks):
        energy.append(cutting_energy(samples[k * WINDOW : (k + 1) * WINDOW]))
        rate.append(ticks["removal_rate"][k * 100 - 20 : (k + 1) * 100].mean())
    assert np.count_nonzero(rate) >= 10
    assert spearman(energy, rate) > 0.8
    assert np.corrcoef(energy, rate)[0, 1] > 0.9  # energy, not amplitude, follows the rate


def test_the_cutting_energy_doubles_with_the_rate_and_its_band_follows_hardness():
    energies = []
    for rate in (10e-9, 20e-9, 40e-9):
        samples = render_drill_sound(**ticks_of(1000, removal_rate=rate))
        energies.append(cutting_energy(samples[-4 * WINDOW :]))
    assert energies[1] / energies[0] == pytest.approx(2, rel=0.25)
    assert energies[2] / energies[1] == pytest.approx(2, rel=0.25)

    def centre(hardness):
        samples = render_drill_sound(**ticks_of(1000, removal_rate=30e-9, hardness=hardness))
        freqs, power = spectrum(samples[-4 * WINDOW :])
        band = freqs > 1000  # above the motor's strongest harmonics
        return float((freqs[band] * power[band]).sum() / power[band].sum())

    soft, bone, hard = centre(0.3), centre(1.0), centre(2.0)
    assert soft < bone - 300 and bone < hard - 300, (soft, bone, hard)


# -- silence -----------------------------------------------------------------------------------


def test_silence_while_the_burr_is_off(session):
    s, ticks, samples = session
    on = ticks["on"]
    first = int(np.argmax(on))
    assert first > 100, "the session starts with the burr off"
    assert np.all(samples[: first * 48] == 0.0)
    assert np.abs(samples[first * 48 : (first + 200) * 48]).max() > 0.01
    # The session, then the burr off for a second: exactly silent 0.5 s after switching off.
    steps = {k: np.asarray(v) for k, v in s.steps.items()}
    n = len(steps["step"])
    tail = {
        "on": np.r_[on, np.zeros(1000)],
        "load": np.r_[ticks["load"], np.zeros(1000)],
        "removal_rate": np.r_[ticks["removal_rate"], np.zeros(1000)],
    }
    padded = render_drill_sound(**tail)
    assert np.array_equal(padded[: n * 48], samples)
    assert np.all(padded[(n + 500) * 48 :] == 0.0)
    # Every stretch off for longer than the coast is silent from 0.5 s in.
    off_runs = np.flatnonzero(np.diff(np.r_[1, on.astype(int)]) == -1)
    for start in off_runs:
        end = start + int(np.argmax(on[start:])) if on[start:].any() else len(on)
        if end - start > 600:
            assert np.all(samples[(start + 500) * 48 : end * 48] == 0.0)


# -- warnings ----------------------------------------------------------------------------------


def beep_onsets(samples: np.ndarray) -> np.ndarray:
    """Sample indices where the tone's envelope rises through half its peak."""
    envelope = np.convolve(np.abs(samples), np.ones(96) / 96, mode="same")
    loud = envelope > 0.5 * envelope.max()
    return np.flatnonzero(loud[1:] & ~loud[:-1]) + 1


def test_the_warning_rate_rises_as_the_distance_falls():
    distances = [0.0012, 0.0009, 0.0006, 0.0003, 0.00005]  # metres, 3 s each
    n = 3000
    column = np.repeat(distances, n)[:, None]
    samples = render_drill_sound(
        np.zeros(len(column)),
        warnings={"Facial_Nerve": 0.001},
        distances=column,
    )
    assert np.all(samples[: n * 48] == 0.0), "no beep beyond the start distance"
    periods = []
    for i in range(1, len(distances)):
        onsets = beep_onsets(samples[i * n * 48 : (i + 1) * n * 48])
        assert len(onsets) >= 3, f"no beeps at {distances[i]} m"
        periods.append(float(np.median(np.diff(onsets))) / RATE)
    assert all(a > b * 1.2 for a, b in zip(periods, periods[1:])), periods
    assert periods[0] < 0.5 and periods[-1] >= 0.08 - 0.005


def test_the_nearest_structure_beeps_at_its_own_pitch():
    column = np.column_stack([np.full(2000, 0.0004), np.full(2000, 0.002)])
    samples = render_drill_sound(
        np.zeros(2000),
        warnings={"Facial_Nerve": {"frequency": 1000.0}, "Sinus_+_Dura": {"frequency": 2500.0}},
        distances=column,
    )
    freqs, power = spectrum(samples)
    assert freqs[np.argmax(power)] == pytest.approx(1000, abs=5)


# -- determinism and the WAV file --------------------------------------------------------------


def test_renders_are_deterministic_and_seeded(session):
    s, ticks, samples = session
    again = render_session(s.steps, s.removed, s.drill.name, s.drill.volume.data.voxel_size)
    assert np.array_equal(samples, again)
    other = render_session(s.steps, s.removed, s.drill.name, s.drill.volume.data.voxel_size, seed=1)
    assert not np.array_equal(samples, other)


def test_render_wav_writes_the_recordings_sound(tmp_path):
    s = drill_phantom(novice_like, 5, 2.0, PROTECT, resolution=64)
    path = tmp_path / "session.h5"
    size = [float(v) for v in s.drill.volume.data.voxel_size]
    legend = {
        "1": {"name": s.drill.name, "kind": "drill"},
        "2": {"name": s.drill.volume.name, "kind": "volume", "voxel_size": size},
    }
    with Recorder(path) as recorder:
        recorder.set_legend(legend)
        recorder.add_steps(s.steps)
        recorder.add_removed(s.removed, volume=s.drill.volume.name)
    wav = render_wav(open_recording(path), tmp_path / "session.wav")
    with wave.open(str(wav)) as w:
        assert (w.getnchannels(), w.getsampwidth(), w.getframerate()) == (1, 2, RATE)
        pcm = np.frombuffer(w.readframes(w.getnframes()), "<i2")
    expected = render_session(s.steps, s.removed, s.drill.name, s.drill.volume.data.voxel_size)
    assert len(pcm) == len(expected) == 2000 * 48
    assert np.abs(pcm / 32767 - expected).max() < 1 / 32767
    assert render_wav(path, tmp_path / "again.wav").read_bytes() == wav.read_bytes()
    # A drill under a namespace: its step-log columns carry its key (psm1/drill); the render
    # finds it by default, by key and by its declared name, and sounds the same.
    key = f"psm1/{s.drill.name}"
    steps = {
        (key + name[len(s.drill.name) :] if name.startswith(s.drill.name + ".") else name): v
        for name, v in s.steps.items()
    }
    spaced = tmp_path / "namespaced.h5"
    with Recorder(spaced) as recorder:
        recorder.set_legend({**legend, "1": {**legend["1"], "key": key}})
        recorder.add_steps(steps)
        recorder.add_removed(s.removed, volume=s.drill.volume.name)
    for drill in (None, key, s.drill.name):
        out = render_wav(spaced, tmp_path / f"ns_{drill is None}_{drill == key}.wav", drill=drill)
        assert out.read_bytes() == wav.read_bytes(), drill


def test_bad_ticks_are_refused():
    with pytest.raises(ambfplus.ArgumentError, match="distances"):
        render_drill_sound(np.zeros(10), warnings={"x": 0.001})
    with pytest.raises(ambfplus.ArgumentError, match="load"):
        render_drill_sound(np.zeros(10), np.zeros(9))
    with pytest.raises(ambfplus.ArgumentError, match="sample_rate"):
        render_drill_sound(np.zeros(10), sample_rate=10)
    with pytest.raises(ambfplus.ArgumentTypeError, match="unknown key"):
        render_drill_sound(np.zeros(10), warnings={"x": {"begin": 1}}, distances=np.ones((10, 1)))


# -- live --------------------------------------------------------------------------------------


def scripted_phantom(seconds: float, seed: int = 3):
    scene = drilling_phantom(resolution=64)
    world, drill = scene.world, scene.drill
    trainee = novice_like(
        drill.volume, drill.pose[:3, 3], drill.burr_radius, np.random.default_rng(seed)
    )
    trainee.plan(seconds)
    device = ambfplus.ScriptedDevice()
    device.set_callback(trainee, every=10)
    world.add_input_device(scene.device_name, device, drill, **scene.device_options)
    return world, drill


@pytest.mark.parametrize("output", ["null", "virtual"])
def test_the_null_and_virtual_devices_play_what_the_offline_render_gives(output):
    """The engine feeds the player at every step; miniaudio's null device, or the virtual
    sound card on miniaudio's custom backend, pulls it on its own thread at the real rate.
    Ticks queued while paused, then played: sample for sample the offline render of the same
    step log."""
    world, drill = scripted_phantom(2.0)
    n = 2000
    sound = DrillSound(
        drill, output=output, paused=True, warnings={}, max_backlog_ticks=4096,
        trim_backlog=False, capture_seconds=3.0,
    )  # fmt: skip
    assert sound.playing and sound.backend.lower() == output
    world.start_step_log([drill])
    world.step(n)
    steps, removed = world.take_step_log(), drill.take_removed()
    assert sound.stats["pushed"] == n
    sound.paused = False
    deadline = time.monotonic() + 20
    while sound.stats["played"] < n and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.05)
    sound.close()
    played = sound.take_capture()
    expected = render_session(steps, removed, drill.name, drill.volume.data.voxel_size)
    assert sound.stats["played"] == n and sound.stats["dropped"] == 0
    assert len(played) >= len(expected)
    assert np.array_equal(played[: len(expected)], expected)
    assert len(sound.take_latencies()) == n
    if output == "virtual":  # one period per callback, as a sound card asks
        assert sound.stats["frames"] == sound.stats["callbacks"] * sound.period_frames


def test_mute_pause_and_stats():
    world, drill = scripted_phantom(0.5)
    with DrillSound(drill, output="none", muted=True) as sound:
        assert sound.muted and not sound.playing and sound.device_error is None
        assert sound.toggle_mute() is False and not sound.muted
        sound.set_muted(True)
        assert sound.muted
        world.step(10)
        # Nothing pulls from a player without a device: the queue fills, the haptic side
        # never waits.
        assert sound.stats["pushed"] == 10
        assert [w["name"] for w in sound.warnings] == [
            label.name for label in drill.volume.data.label_table if label.critical
        ]
    assert sound.closed
    world.step(10)  # closed: no longer fed, nothing fails
    with pytest.raises(ambfplus.ArgumentError, match="output"):
        DrillSound(drill, output="speakers")


def test_no_device_says_so_once_and_carries_on_silent(caplog):
    world, drill = scripted_phantom(0.5)
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        first = DrillSound(drill)
        second = DrillSound(drill)
    if first.playing:
        first.close()
        second.close()
        pytest.skip(f"this machine has an audio device ({first.backend})")
    assert "no audio output device" in first.device_error
    warnings = [r for r in caplog.records if "drill sound" in r.getMessage()]
    assert len(warnings) <= 1  # once per process (an earlier test may have said it)
    world.step(20)  # the world steps on, silent
    first.close()
    second.close()
    with pytest.raises(ambfplus.ResourceError, match="no audio output device"):
        DrillSound(drill, require_device=True)


def test_a_recording_replays_the_proximity_warnings(tmp_path):
    """The step log's <drill>.critical_distance column and the legend's list of the drill's
    critical structures let render_wav play the beeps a DrillSound plays by default (each
    critical structure from 1 mm): a plunge toward a nerve beeps in the replay."""
    grid = np.zeros((100, 100, 100), np.uint8)
    grid[:, :, :50] = 1
    grid[45:55, 45:55, 30:40] = 2
    table = [ambfplus.Label(1, "Bone"), ambfplus.Label(2, "Nerve", critical=True)]
    world = ambfplus.World()
    volume = world.add_volume("slab", ambfplus.VolumeData(grid, voxel_size=(0.0002,) * 3,
                                                          label_table=table))  # fmt: skip
    up = ambfplus.rotation_between((1, 0, 0), (0, 0, 1))
    drill = world.add_drill("drill", volume, burr=1, cutting_rate=2e-6, stiffness=2000.0,
                            pose=ambfplus.make_pose((0, 0, 0.008), rotation=up))  # fmt: skip
    r = drill.burr_radius
    drill.set_waypoints([
        {"time": 0.0, "pose": ambfplus.make_pose((0, 0, 0.008), rotation=up), "on": True},
        {"time": 1.0, "pose": ambfplus.make_pose((0, 0, r - 0.0035), rotation=up), "on": True},
    ])  # fmt: skip
    world.start_step_log([drill])
    world.step(1200)
    steps, removed = world.take_step_log(), drill.take_removed()
    column = np.asarray(steps["drill.critical_distance"]).reshape(len(steps["step"]), -1)
    assert column.shape[1] == 1
    assert column[-1, 0] == pytest.approx(drill.critical_distances["Nerve"], abs=1e-12)
    assert column[:, 0].min() < 0.0005, "the burr came within the beep's range"
    legend = {str(k): v for k, v in ambfplus.labels.legend(world).items()}
    assert legend[str(drill.id)]["critical"] == ["Nerve"]
    legend[str(volume.id)]["voxel_size"] = [0.0002] * 3
    path = tmp_path / "plunge.h5"
    with Recorder(path) as recorder:
        recorder.set_legend(legend)
        recorder.add_steps(steps)
        recorder.add_removed(removed, volume=volume.name)
    with wave.open(str(render_wav(path, tmp_path / "plunge.wav"))) as w:
        pcm = np.frombuffer(w.readframes(w.getnframes()), "<i2") / 32767
    size = (0.0002,) * 3
    beeping = render_session(steps, removed, "drill", size, warnings={"Nerve": 0.001},
                             distances=column)  # fmt: skip
    silent = render_session(steps, removed, "drill", size, warnings={})
    assert np.abs(pcm - beeping).max() < 1 / 32767
    assert np.abs(pcm - silent).max() > 0.05, "the replay beeps"
