"""The synthetic microphone track: format, placement truth, claps, drift, noise level."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.errors import UsageError
from speechcal_core.synth.audio import AudioTruth, render_audio
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import Timeline, plan_session


def _render(tmp: Path, **options: object) -> tuple[Timeline, AudioTruth, np.ndarray, int]:
    timeline = plan_session(SynthOptions(**options))  # type: ignore[arg-type]
    out = tmp / "audio.ogg"
    truth = render_audio(timeline, out)
    data, sr = sf.read(str(out), dtype="float64")
    return timeline, truth, data, sr


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory):
    """A 20 s session with two claps and strong drift, default SNR."""
    return _render(tmp_path_factory.mktemp("audio"), duration=20.0, seed=3, claps=2,
                   drift_ppm=150.0, snr_db=20.0)


def _speech_free(truth: AudioTruth, n: int, sr: int) -> np.ndarray:
    """Samples with no speech (plus reverb tail), clap or door nearby."""
    free = np.ones(n, dtype=bool)
    for item in truth.triggers + truth.distractors:
        free[int((item["start_s"] - 0.05) * sr):int((item["end_s"] + 0.6) * sr)] = False
    for c in truth.claps:
        free[int((c - 0.05) * sr):int((c + 0.6) * sr)] = False
    for ev in truth.events:
        free[int((ev["audio_s"] - 0.05) * sr):int((ev["audio_s"] + 1.6) * sr)] = False
    return free


def _speech_mask(truth: AudioTruth, n: int, sr: int) -> np.ndarray:
    mask = np.zeros(n, dtype=bool)
    for item in truth.triggers + truth.distractors:
        mask[int(np.ceil(item["start_s"] * sr)):int(np.ceil(item["end_s"] * sr))] = True
    return mask


def test_audio_is_48k_mono_ogg_of_the_planned_duration(session):
    timeline, truth, data, sr = session
    assert sr == 48_000 and data.ndim == 1
    assert truth.sample_rate == 48_000
    assert len(data) / sr == pytest.approx(truth.duration_s, abs=1e-3)
    assert truth.duration_s == pytest.approx(timeline.audio_duration_s, abs=1e-3)


def test_every_trigger_is_audible_where_the_truth_says(session):
    _, truth, data, sr = session
    noise = np.mean(data[_speech_free(truth, len(data), sr)] ** 2)
    assert len(truth.triggers) >= 3
    for trig in truth.triggers:
        assert trig["word"] == "capture"
        inside = np.mean(data[int(trig["start_s"] * sr):int(trig["end_s"] * sr)] ** 2)
        assert 10 * np.log10(inside / noise) > 10.0, trig


@pytest.mark.parametrize("snr_db", [8.0, 25.0])
def test_snr_option_sets_speech_to_noise_ratio(tmp_path, snr_db):
    _, truth, data, sr = _render(tmp_path, duration=12.0, seed=5, snr_db=snr_db)
    assert truth.speech_rms / truth.noise_rms == pytest.approx(10 ** (snr_db / 20))
    noise = np.mean(data[_speech_free(truth, len(data), sr)] ** 2)
    speech = np.mean(data[_speech_mask(truth, len(data), sr)] ** 2) - noise
    assert 10 * np.log10(speech / noise) == pytest.approx(snr_db, abs=1.5)


def test_clap_onset_in_the_file_is_at_the_truth_time(session):
    _, truth, data, sr = session
    assert len(truth.claps) == 2
    for clap in truth.claps:
        k = round(clap * sr)
        near = np.abs(data[k - sr // 100:k + sr // 50])  # 10 ms before to 20 ms after
        first = np.flatnonzero(near > 0.2 * near.max())[0] + k - sr // 100
        assert abs(first / sr - clap) < 0.001


def test_clap_is_louder_than_any_speech(session):
    _, truth, data, sr = session
    speech = _speech_mask(truth, len(data), sr)
    for ev in truth.events:  # the door may have to share a moment with chatter
        speech[int(ev["audio_s"] * sr):int((ev["audio_s"] + 1.0) * sr)] = False
    speech_peak = np.max(np.abs(data[speech]))
    for clap in truth.claps:
        k = int(np.ceil(clap * sr))
        assert np.max(np.abs(data[k:k + sr // 20])) > 1.5 * speech_peak


def test_truth_times_follow_the_drifting_sync_model(session):
    timeline, truth, _, _ = session
    sync = timeline.sync
    assert sync.drift == pytest.approx(150e-6)
    assert truth.claps == [sync.to_audio(c) for c in timeline.claps_ns]
    slots = {s.hold: s for s in timeline.speech if s.kind == "trigger"}
    assert sorted(slots) == [t["hold"] for t in truth.triggers]
    for trig in truth.triggers:
        slot = slots[trig["hold"]]
        placed = (trig["start_s"] + trig["end_s"]) / 2 if slot.align == "center" else trig["end_s"]
        assert placed == pytest.approx(sync.to_audio(slot.anchor_ns), abs=1e-9)
    # the drift matters: ignoring it would misplace the last trigger by more than 1 ms
    last = timeline.speech[-1].anchor_ns
    assert abs(sync.to_audio(last) - (last - sync.offset_ns) / 1e9) > 0.001


def test_hard_cases_for_clap_detection_are_present(session):
    _, truth, data, sr = session
    first = truth.claps[0]
    before = [d for d in truth.distractors if d["end_s"] < first]
    assert len(before) == 1 and 0.2 <= first - before[0]["end_s"] <= 1.0
    (door,) = truth.events
    assert door["kind"] == "door"
    for trig in truth.triggers:
        assert door["audio_s"] < trig["start_s"] - 1.0 or door["audio_s"] > trig["end_s"] + 1.0
    k = int(np.ceil(door["audio_s"] * sr))
    noise = np.sqrt(np.mean(data[_speech_free(truth, len(data), sr)] ** 2))
    assert np.max(np.abs(data[k:k + sr // 2])) > 20 * noise


def test_rendering_is_deterministic_by_seed(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = _render(tmp_path / "a", duration=8.0, seed=9, triggers=1)
    b = _render(tmp_path / "b", duration=8.0, seed=9, triggers=1)
    assert a[1] == b[1]
    np.testing.assert_array_equal(a[2], b[2])


def test_other_bundled_trigger_word_is_spoken(tmp_path):
    _, truth, _, _ = _render(tmp_path, duration=8.0, seed=2, trigger_word="Snapshot")
    assert truth.triggers and all(t["word"] == "snapshot" for t in truth.triggers)


def test_unbundled_trigger_word_is_a_usage_error(tmp_path):
    timeline = plan_session(SynthOptions(duration=6.0, trigger_word="cheese"))
    with pytest.raises(UsageError, match="capture"):
        render_audio(timeline, tmp_path / "audio.ogg")
    assert not (tmp_path / "audio.ogg").exists()


def test_word_starts_where_the_truth_says_in_a_quiet_render(tmp_path):
    _, truth, data, sr = _render(tmp_path, duration=15.0, seed=4, snr_db=60.0, drift_ppm=80.0)
    ends = [d["end_s"] for d in truth.distractors + truth.triggers]
    checked = 0
    for trig in truth.triggers:
        if any(trig["start_s"] - 0.7 < e < trig["start_s"] for e in ends):
            continue  # another word's reverb tail would hide the onset
        a, b = int(np.ceil(trig["start_s"] * sr)), int(np.ceil(trig["end_s"] * sr))
        level = np.abs(data[a - sr // 10:b])
        first = np.flatnonzero(level > 10 ** (-30 / 20) * level.max())[0] - sr // 10
        assert -0.001 <= first / sr <= 0.04, trig
        checked += 1
    assert checked >= 2


def test_progress_reports_rise_to_one(tmp_path):
    seen: list[float] = []
    render_audio(plan_session(SynthOptions(duration=6.0, seed=1)), tmp_path / "audio.ogg",
                 progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) >= 3


def test_distractors_mix_near_homophones_and_chatter_clear_of_triggers(tmp_path):
    _, truth, _, _ = _render(tmp_path, duration=40.0, seed=11, snr_db=30.0)
    near = [d for d in truth.distractors if d["near"] == "capture"]
    assert near and len(near) < len(truth.distractors)
    for d in truth.distractors:
        for t in truth.triggers:
            assert d["end_s"] <= t["start_s"] - 0.1 or d["start_s"] >= t["end_s"] + 0.1
    assert len({t["voice"] for t in truth.triggers}) >= 2
    assert {t["voice"] for t in truth.triggers} <= {"slt", "rms", "awb", "kal16"}
