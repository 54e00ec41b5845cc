"""The digest of what the checks are computed over follows every change of the sets."""

from __future__ import annotations

import json

import pytest

from speechcal_core.frames.analysis import checks_basis
from speechcal_core.session.model import FrameChoice, FrameSet, Trigger


def _sets() -> list[FrameSet]:
    return [FrameSet(i, 10**18 + i * 10**9, Trigger("capture", i, i + 0.4),
                     (FrameChoice("/cam0/image_raw", 3 * i, 10**18 + i * 10**9),
                      FrameChoice("/cam1/image_raw", 3 * i, 10**18 + i * 10**9 + 5)))
            for i in range(1, 6)]


def test_the_same_sets_are_digested_once_and_any_change_digests_anew(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The window asks for the digest of the same (immutable) sets several times per
    action: it is computed once; a set replaced, added or removed changes it."""
    sets = _sets()
    first = checks_basis(sets)
    encoded: list[object] = []
    real = json.dumps
    monkeypatch.setattr(json, "dumps", lambda *a, **k: encoded.append(a[0]) or real(*a, **k))
    assert checks_basis(list(sets)) == first and encoded == []
    rejected = [sets[0].with_decision("rejected"), *sets[1:]]
    assert checks_basis(rejected) != first and len(encoded) == 1
    assert checks_basis(sets[:-1]) != first
    assert checks_basis(sets) == first  # the same sets again, digested as before
    assert checks_basis([*sets[:2], sets[2].with_decision("accepted"), *sets[3:]]) == first
