"""The bundled voice clips: inventory, trimming, trigger-word lookup."""

from __future__ import annotations

from collections import defaultdict

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.errors import UsageError
from speechcal_core.resources import resource
from speechcal_core.synth.voices import available_trigger_words, check_trigger_word, load_bank

NEAR_HOMOPHONES = ("picture", "rapture", "captain", "captured it?")
CHATTER = ("okay", "move it left", "a bit closer", "hold on", "ready", "tilt it up", "nice",
           "one more")


def test_required_trigger_words_are_bundled_in_several_voices_and_takes():
    bank = load_bank()
    assert {"capture", "snapshot", "record", "mark"} <= set(available_trigger_words())
    for word in ("capture", "snapshot", "record", "mark"):
        takes: dict[str, set[int]] = defaultdict(set)
        for clip in bank.select("trigger", word):
            takes[clip.voice].add(clip.take)
        human = [v for v in takes if v in ("slt", "rms", "awb", "kal16")]
        assert len(human) >= 3, (word, takes)
        assert all(len(takes[v]) >= 3 for v in human), (word, takes)


def test_distractors_include_near_homophones_and_chatter_in_several_voices():
    bank = load_bank()
    for text in NEAR_HOMOPHONES + CHATTER:
        clips = bank.select("distractor", text)
        assert len({c.voice for c in clips}) >= 3, text
    assert all(c.near == "capture" for t in NEAR_HOMOPHONES for c in bank.select(text=t))
    assert not bank.select("distractor", "capture")


def test_clip_files_match_index_and_are_trimmed_to_the_spoken_part():
    bank = load_bank()
    for clip in bank.clips:
        info = sf.info(str(bank.folder / clip.file))
        assert info.samplerate == bank.sample_rate and info.channels == 1, clip.file
        assert info.frames / info.samplerate == pytest.approx(clip.duration_s, abs=1e-4)
        x = bank.samples(clip)
        fr = bank.sample_rate // 500  # 2 ms frames
        n = len(x) // fr
        level = 20 * np.log10(np.sqrt(np.mean(x[: n * fr].reshape(n, fr) ** 2, axis=1)) + 1e-12)
        loud = level > level.max() - 36.0
        edge = int(0.03 * bank.sample_rate) // fr
        assert loud[:edge].any() and loud[-edge:].any(), f"{clip.file} has silent edges"


def test_voice_resources_stay_small():
    total = sum(p.stat().st_size for p in resource("voices").rglob("*") if p.is_file())
    assert total < 8_000_000


def test_trigger_word_lookup_normalizes_case():
    assert check_trigger_word(" Capture ") == "capture"


def test_unknown_trigger_word_names_the_bundled_words():
    with pytest.raises(UsageError) as err:
        check_trigger_word("cheese")
    message = str(err.value)
    assert "cheese" in message
    assert all(word in message for word in available_trigger_words())
