"""The PCM the review window plays: stretches of real audio files as int16 mono, by audio
seconds, session time or a set's trigger word, clipped to the file; how far a stretch's
sound has got, and how often a dragged playhead restarts it."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from audio_files import write_gated_tone, write_spliced_ogg
from truth_sessions import quiet_time_s

from speechcal_core.audio import load_audio
from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.playback import (
    BY_HAND_SPAN_S,
    RESTART_INTERVAL_S,
    WORD_MARGIN_S,
    PlaybackAudio,
    RestartThrottle,
    heard_s,
)
from speechcal_core.session.model import Trigger
from speechcal_core.sync.model import SyncModel

RATE = 48000


def _ints(path: Path, rate: int = RATE, seconds: float = 6.0) -> np.ndarray:
    """A mono 16-bit WAV of known integer samples (a gated tone in noise)."""
    write_gated_tone(path, rate, seconds, 1, seed=3, tone_hz=330.0, gate_hz=1.3,
                     subtype="PCM_16")
    return sf.read(str(path), dtype="int16")[0]


def test_a_stretch_is_the_files_16_bit_samples(tmp_path: Path) -> None:
    ints = _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    assert audio.rate == RATE and audio.duration_s == pytest.approx(6.0)
    clip = audio.clip(1.0, 2.5)
    assert clip.pcm.dtype == np.int16 and clip.rate == RATE and clip.start_s == 1.0
    np.testing.assert_array_equal(clip.pcm, ints[RATE:int(2.5 * RATE)])
    assert clip.duration_s == pytest.approx(1.5)
    assert clip.to_bytes() == ints[RATE:int(2.5 * RATE)].astype("<i2").tobytes()


def test_stretches_are_clipped_to_the_file(tmp_path: Path) -> None:
    ints = _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    head = audio.clip(-0.5, 0.3)
    assert head.start_s == 0.0
    np.testing.assert_array_equal(head.pcm, ints[:int(0.3 * RATE)])
    tail = audio.clip(5.8, 7.0)
    assert tail.pcm.size == int(0.2 * RATE) and tail.end_s == pytest.approx(6.0)
    np.testing.assert_array_equal(tail.pcm, ints[int(5.8 * RATE):])
    assert audio.clip(6.5, 8.0).pcm.size == 0
    assert audio.clip(-3.0, -1.0).pcm.size == 0
    assert audio.clip(2.0, 1.0).pcm.size == 0


def test_session_time_goes_through_the_sync(tmp_path: Path) -> None:
    ints = _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    sync = SyncModel(offset_ns=1_700_000_000_000_000_000 - 2_000_000_000, drift=30e-6)
    clip = audio.session_clip(sync.to_session(1.25), sync.to_session(3.25), sync)
    assert clip.start_s == pytest.approx(1.25, abs=1 / RATE)
    a = round(clip.start_s * RATE)
    np.testing.assert_array_equal(clip.pcm, ints[a:a + clip.pcm.size])
    assert clip.pcm.size == pytest.approx(2 * RATE, abs=1)


def test_a_words_stretch_has_its_margin(tmp_path: Path) -> None:
    ints = _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    clip, span = audio.word(Trigger("capture", 2.0, 2.4))
    assert not span.by_hand
    assert (span.start_s, span.end_s) == (2.0 - WORD_MARGIN_S, 2.4 + WORD_MARGIN_S)
    assert clip.start_s == pytest.approx(1.75)
    a = int(1.75 * RATE)
    np.testing.assert_array_equal(clip.pcm, ints[a:a + int(0.9 * RATE)])
    early, _ = audio.word(Trigger("capture", 0.1, 0.5))  # margin clipped at the start
    np.testing.assert_array_equal(early.pcm, ints[:int(0.75 * RATE)])


def test_a_set_added_by_hand_plays_a_second_around_its_time(tmp_path: Path) -> None:
    _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    clip, span = audio.word(Trigger("capture", 3.0, 3.0, source="manual"))
    assert span.by_hand and span.end_s - span.start_s == BY_HAND_SPAN_S
    assert clip.start_s == pytest.approx(2.5) and clip.duration_s == pytest.approx(1.0)
    late, _ = audio.word(Trigger("capture", 5.9, 5.9, source="manual"))
    assert late.start_s == pytest.approx(5.4) and late.end_s == pytest.approx(6.0)


@pytest.mark.parametrize(("name", "channels", "kw"), [
    ("a.ogg", 2, {"format": "OGG", "subtype": "VORBIS"}),  # seeks need the pre-roll
    ("a.flac", 1, {}),
])
def test_blocks_put_together_are_the_stretch(tmp_path: Path, name: str, channels: int,
                                             kw: dict) -> None:
    p = write_gated_tone(tmp_path / name, 44100, 5.0, channels, seed=2, tone_hz=500.0,
                         gate_hz=0.9, **kw)
    audio = PlaybackAudio(p)
    blocks = list(audio.blocks(1.3, 3.05, block_s=0.25))
    assert [round(b.duration_s, 3) for b in blocks] == [0.25] * 7
    assert blocks[0].start_s == pytest.approx(1.3, abs=1 / 44100)
    whole = audio.clip(1.3, 3.05)
    np.testing.assert_array_equal(np.concatenate([b.pcm for b in blocks]), whole.pcm)
    mono = sf.read(str(p), dtype="float32", always_2d=True)[0].mean(axis=1)
    a = round(1.3 * 44100)
    expected = np.clip(np.rint(mono[a:a + whole.pcm.size] * 32768), -32768, 32767)
    np.testing.assert_array_equal(whole.pcm, expected.astype(np.int16))
    to_end = list(audio.blocks(4.1))
    assert to_end[-1].end_s == pytest.approx(5.0)
    assert sum(b.pcm.size for b in to_end) == round(0.9 * 44100)


def test_a_start_before_the_file_plays_silence_until_it_starts(tmp_path: Path) -> None:
    ints = _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    assert audio.start_index(-0.6, lead_in=True) == -round(0.6 * RATE)
    assert audio.start_index(-0.6) == 0
    blocks = list(audio.blocks(-0.6, 0.8, block_s=0.25, lead_in=True))
    assert blocks[0].start_s == pytest.approx(-0.6)
    assert [round(b.duration_s, 3) for b in blocks] == [0.25] * 5 + [0.15]
    pcm = np.concatenate([b.pcm for b in blocks])
    lead = round(0.6 * RATE)
    assert not pcm[:lead].any()  # silence, the block across 0 s included
    np.testing.assert_array_equal(pcm[lead:], ints[:round(0.8 * RATE)])
    assert next(audio.blocks(-0.6, 0.8, block_s=0.25)).start_s == 0.0  # no lead-in
    assert audio.start_index(7.0, lead_in=True) == audio.samples.size  # past the end
    assert list(audio.blocks(7.0, lead_in=True)) == []


def test_another_rate_is_resampled(tmp_path: Path) -> None:
    _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav", rate=44100)
    clip = audio.clip(1.0, 3.0)
    assert clip.rate == 44100 and clip.pcm.size == 2 * 44100


def test_the_words_in_a_synthetic_session_are_louder_than_its_quiet(tiny_synth) -> None:
    folder, truth = tiny_synth
    audio = PlaybackAudio(folder / truth["audio"])
    quiet = audio.clip(quiet_time_s(truth, 1.0) - 0.2, quiet_time_s(truth, 1.0) + 0.2)
    level = float(np.sqrt(np.mean(quiet.pcm.astype(np.float64) ** 2)))
    for t in truth["triggers"]:
        clip, _span = audio.word(Trigger(t["word"], t["start_s"], t["end_s"]))
        assert clip.duration_s == pytest.approx(t["end_s"] - t["start_s"] + 0.5, abs=1e-3)
        word = clip.pcm[round(WORD_MARGIN_S * clip.rate):-round(WORD_MARGIN_S * clip.rate)]
        assert np.sqrt(np.mean(word.astype(np.float64) ** 2)) > 3 * level, t


def test_a_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(AudioError, match=r"gone\.wav: audio file not found"):
        PlaybackAudio(tmp_path / "gone.wav")


def test_a_file_moved_after_opening_is_named(tmp_path: Path) -> None:
    _ints(tmp_path / "a.wav")
    audio = PlaybackAudio(tmp_path / "a.wav")
    shutil.move(tmp_path / "a.wav", tmp_path / "b.wav")
    with pytest.raises(AudioError, match=r"a\.wav: could not read the audio again"):
        audio.clip(1.0, 2.0)


def test_the_sound_has_got_as_far_as_the_output_has_processed() -> None:
    rate = 48000
    # nothing processed yet (an output still starting): the stretch's start
    assert heard_s(12.5, rate, written=9600, buffered=9600, processed_us=0) == 12.5
    # PySide6 6.11 on PulseAudio: processed is what left the buffer
    assert heard_s(12.5, rate, written=48000, buffered=9600,
                   processed_us=800_000) == pytest.approx(13.3)
    # an output counting what it holds: never past what has left the buffer
    assert heard_s(12.5, rate, written=48000, buffered=9600,
                   processed_us=1_000_000) == pytest.approx(13.3)
    # one behind that (played, latency taken off): its own figure
    assert heard_s(12.5, rate, written=48000, buffered=9600,
                   processed_us=650_000) == pytest.approx(13.15)
    assert heard_s(-0.5, rate, written=0, buffered=0, processed_us=0) == -0.5  # lead-in


def test_a_drag_restarts_the_sound_at_most_once_per_interval() -> None:
    throttle = RestartThrottle(0.12)
    assert throttle.request(10.0) == 0.0  # the first move: at once
    throttle.done(10.0)
    moves = [10.0 + 0.01 * k for k in range(1, 100)]  # a second of mouse moves, 10 ms apart
    restarts = [10.0]
    waits = []
    for now in moves:
        wait = throttle.request(now)
        if wait == 0:
            throttle.done(now)
            restarts.append(now)
        elif wait is not None:
            waits.append(now + wait)
        if waits and now >= waits[0]:  # the single-shot timer fires
            throttle.done(waits.pop(0))
            restarts.append(now)
    assert np.diff(restarts).min() >= 0.12 - 1e-9
    assert 7 <= len(restarts) <= 10  # a second / 0.12 s, not a hundred
    assert 0.1 <= RESTART_INTERVAL_S <= 0.15  # short enough to follow a drag by ear


def test_a_move_after_a_quiet_interval_restarts_at_once() -> None:
    throttle = RestartThrottle(0.12)
    throttle.done(5.0)
    assert throttle.request(5.05) == pytest.approx(0.07)  # waits for the interval's end
    assert throttle.pending
    assert throttle.request(5.08) is None  # already waiting: one restart for both
    throttle.done(5.12)
    assert not throttle.pending
    assert throttle.request(5.40) == 0.0
    throttle.done(5.40)
    assert throttle.request(5.45) == pytest.approx(0.07)
    throttle.cancel()  # paused: nothing waits, and the next play is not held back
    assert not throttle.pending
    assert throttle.request(5.70) == 0.0


def test_playback_and_search_read_the_sessions_channel(tmp_path: Path) -> None:
    """A two-channel file whose microphone is on channel 1: the window plays that channel
    (mixed it was half as loud, with the other input's noise) and the search indexes it."""
    from speechcal_core.review.similar import SessionAudio

    rate = 16000
    tone = 0.5 * np.sin(2 * np.pi * 220 * np.arange(rate) / rate).astype(np.float32)
    both = np.zeros((rate, 2), np.float32)
    both[:, 1] = tone
    path = tmp_path / "stereo.wav"
    sf.write(path, both, rate)
    mic = PlaybackAudio(path, channel=1).clip(0.25, 0.5)
    mixed = PlaybackAudio(path).clip(0.25, 0.5)
    assert np.abs(mic.pcm).max() == pytest.approx(0.5 * 32768, rel=0.01)
    assert np.abs(mixed.pcm).max() == pytest.approx(0.25 * 32768, rel=0.01)
    assert SessionAudio(path, channel=1).index().samples.read(0, 4000).max() > 0.4
    assert SessionAudio(path, channel=0).index().samples.read(0, 4000).max() == 0.0


def test_a_file_whose_header_does_not_know_its_length_plays_what_decodes(
        tmp_path: Path) -> None:
    p = write_spliced_ogg(tmp_path / "spliced.ogg", 16000, 40.0, seed=3)
    audio = PlaybackAudio(p)
    decoded = load_audio(p).samples
    assert audio.duration_s == pytest.approx(decoded.size / 16000)
    stretch = audio.samples[16000:20000]
    assert stretch.size == 4000 and np.any(stretch != 0)
