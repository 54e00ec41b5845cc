"""Atomic writes and staged output folders never leave half-written results."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from speechcal_core.fsutil import OutputExistsError, atomic_write_text, staged_directory


def test_atomic_write_keeps_previous_version_as_bak(tmp_path: Path) -> None:
    target = tmp_path / "session.json"
    atomic_write_text(target, "one")
    atomic_write_text(target, "two", keep_backup=True)
    assert target.read_text() == "two"
    assert (tmp_path / "session.json.bak").read_text() == "one"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["session.json", "session.json.bak"]


def test_staged_directory_appears_only_when_complete(tmp_path: Path) -> None:
    target = tmp_path / "out"
    with pytest.raises(RuntimeError), staged_directory(target) as staging:
        (staging / "half.txt").write_text("x")
        raise RuntimeError("failed midway")
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []
    with staged_directory(target) as staging:
        (staging / "done.txt").write_text("x")
    assert (target / "done.txt").exists()


def test_existing_output_needs_force(tmp_path: Path) -> None:
    target = tmp_path / "out"
    target.mkdir()
    (target / "old.txt").write_text("keep me")
    with pytest.raises(OutputExistsError, match="--force"), staged_directory(target):
        pass
    assert (target / "old.txt").read_text() == "keep me"
    with staged_directory(target, force=True) as staging:
        (staging / "new.txt").write_text("x")
    assert sorted(p.name for p in target.iterdir()) == ["new.txt"]


def test_written_files_and_folders_get_ordinary_permissions(tmp_path: Path) -> None:
    with staged_directory(tmp_path / "out") as staging:
        atomic_write_text(staging / "a.json", "{}")
    mask = os.umask(0)
    os.umask(mask)
    assert (tmp_path / "out").stat().st_mode & 0o777 == 0o777 & ~mask
    assert (tmp_path / "out" / "a.json").stat().st_mode & 0o777 == 0o666 & ~mask
