"""Session files for export tests: reviewed sets over a synthetic or exported recording."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

#: decisions given to the sets in turn
PATTERN = ("accepted", "undecided", "accepted", "rejected")


def write_session(folder: Path, truth: dict, path: Path,
                  decisions: Sequence[str] = PATTERN) -> Path:
    """A session file over ``folder``'s recording: one set per true trigger, with
    ``decisions`` in turn and made-up quality figures on every chosen frame."""
    from truth_sessions import truth_session

    from speechcal_core.session.store import save_session

    session = truth_session(folder, truth)
    sets = [
        replace(s, decision=decisions[k % len(decisions)], frames=tuple(
            replace(f, sharpness=round(100.0 + 10 * k + j + 0.25, 2), corners=140 + j,
                    flags=("blur",) if j == 1 else ())
            for j, f in enumerate(s.frames)))
        for k, s in enumerate(session.sets)
    ]
    session.sets = sets
    path.parent.mkdir(parents=True, exist_ok=True)
    save_session(session, path)
    return path


def accepted_sets_over(source, streams: Sequence[str]):
    """A session over an image-folder ``source``: one accepted set per stamp of the first
    stream, taking that frame index in every stream."""
    from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
    from speechcal_core.sync.model import SyncModel

    stamps = source.stamps(streams[0])
    sets = [FrameSet(k + 1, int(t), Trigger("capture", k, k + 0.5),
                     tuple(FrameChoice(n, k, int(source.stamps(n)[k])) for n in streams),
                     "accepted")
            for k, t in enumerate(stamps)]
    root = getattr(source, "root", "")
    return Session([str(root)], None, SyncModel(0, 0.0, "manual"), sets)
