"""Where the synthetic operator speaks: one voice never says two words at once."""

from __future__ import annotations

from itertools import pairwise

from speechcal_core.synth.audio import _plan_speech
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import plan_session
from speechcal_core.synth.voices import load_bank


def test_trigger_words_never_overlap_even_when_said_while_the_board_settles() -> None:
    bank = load_bank()
    for seed in range(30):
        timeline = plan_session(SynthOptions(duration=200.0, seed=seed))
        claps = [float(timeline.sync.to_audio(c)) for c in timeline.claps_ns]
        placed = _plan_speech(timeline, bank, "capture", claps, timeline.rng("audio"))
        words = [p for p in placed if p.kind == "trigger"]
        for a, b in pairwise(words):
            assert b.start_s >= a.end_s + 0.1, (seed, a.start_s, b.start_s)
