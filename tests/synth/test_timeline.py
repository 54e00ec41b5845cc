"""The session plan: holds, trigger slots, claps and clocks agree with the options."""

from __future__ import annotations

import numpy as np
import pytest

from speechcal_core.errors import UsageError
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import HOLD_RANGE_S, NS, plan_session


def test_same_seed_same_plan_other_seed_other_plan() -> None:
    a = plan_session(SynthOptions(duration=20, seed=3))
    b = plan_session(SynthOptions(duration=20, seed=3))
    c = plan_session(SynthOptions(duration=20, seed=4))
    assert a.segments == b.segments and a.speech == b.speech and a.sync == b.sync
    assert a.segments != c.segments


def test_every_trigger_slot_belongs_to_a_hold_of_the_right_length() -> None:
    plan = plan_session(SynthOptions(duration=40, seed=1))
    holds = plan.holds
    triggers = [s for s in plan.speech if s.kind == "trigger"]
    assert len(triggers) == len(holds) > 5
    for slot in triggers:
        hold = holds[slot.hold]
        assert HOLD_RANGE_S[0] * NS <= hold.end_ns - hold.start_ns <= HOLD_RANGE_S[1] * NS
        if slot.align == "center":
            assert hold.start_ns < slot.anchor_ns < hold.end_ns
        else:  # said while settling: ends at most 0.3 s before the hold starts
            assert hold.start_ns - 0.3 * NS <= slot.anchor_ns <= hold.start_ns


def test_pose_is_constant_in_holds_and_moves_between_them() -> None:
    plan = plan_session(SynthOptions(duration=20, seed=2))
    hold = plan.holds[1]
    r0, t0 = plan.pose_at(hold.start_ns + 1)
    r1, t1 = plan.pose_at(hold.end_ns - 1)
    assert np.allclose(r0, r1) and np.allclose(t0, t1)
    move = next(s for s in plan.segments if s.kind == "move")
    _, a = plan.pose_at(move.start_ns)
    _, m = plan.pose_at((move.start_ns + move.end_ns) // 2)
    assert np.linalg.norm(m - a) > 1e-3


def test_two_claps_and_audio_clock_cover_the_recording() -> None:
    plan = plan_session(SynthOptions(duration=30, claps=2, drift_ppm=20, seed=5))
    assert len(plan.claps_ns) == 2
    assert plan.start_ns < plan.claps_ns[0] < plan.claps_ns[1] < plan.end_ns
    assert plan.sync.drift == pytest.approx(20e-6)
    assert plan.sync.to_audio(plan.start_ns) > 0  # audio started before the first frame
    assert plan.audio_duration_s > plan.sync.to_audio(plan.end_ns)


def test_too_many_triggers_for_the_duration_names_the_fix() -> None:
    with pytest.raises(UsageError, match="longer --duration"):
        plan_session(SynthOptions(duration=10, triggers=30))
