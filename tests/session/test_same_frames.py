"""Two triggers in one still hold take the same frames: one view, marked, written once."""

from __future__ import annotations

from speechcal_core.session.model import FrameChoice, FrameSet, Trigger
from speechcal_core.session.same_frames import first_of_same_frames, same_frames


def _set(set_id: int, indices: tuple[int, int], t_s: float) -> FrameSet:
    frames = tuple(FrameChoice(f"/cam{k}", i, 1_000 * i) for k, i in enumerate(indices))
    return FrameSet(set_id, int(t_s * 1e9), Trigger("capture", t_s, t_s + 0.4), frames)


def test_sets_showing_the_same_frames_name_each_other() -> None:
    sets = [_set(1, (10, 12), 1.0), _set(2, (40, 41), 4.0), _set(3, (40, 41), 4.6),
            _set(4, (40, 42), 5.0), _set(5, (-1, -1), 9.0), _set(6, (-1, -1), 9.5)]
    assert same_frames(sets) == {2: (3,), 3: (2,)}  # no frame at all is no frame shared


def test_only_the_first_of_sets_with_the_same_frames_is_kept() -> None:
    sets = [_set(1, (10, 12), 1.0), _set(2, (40, 41), 4.0), _set(3, (40, 41), 4.6),
            _set(4, (40, 41), 4.9), _set(5, (50, 52), 6.0)]
    kept, dropped = first_of_same_frames(sets)
    assert [s.id for s in kept] == [1, 2, 5]
    assert dropped == {3: 2, 4: 2}
