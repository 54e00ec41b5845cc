"""Atomic writes and staged output folders never leave half-written results."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest

from speechcal_core.errors import SpeechCalError
from speechcal_core.fsutil import (
    OutputExistsError,
    atomic_write_text,
    folder_write_problem,
    overlap,
    staged_directory,
)


def test_atomic_write_keeps_previous_version_as_bak(tmp_path: Path) -> None:
    target = tmp_path / "session.json"
    atomic_write_text(target, "one")
    atomic_write_text(target, "two", keep_backup=True)
    assert target.read_text() == "two"
    assert (tmp_path / "session.json.bak").read_text() == "one"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["session.json", "session.json.bak"]


BACKUP_FAILS = textwrap.dedent("""
    import resource, signal, sys
    from speechcal_core.fsutil import atomic_write_text
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails: EFBIG
    resource.setrlimit(resource.RLIMIT_FSIZE, (1000, 1000))
    try:
        atomic_write_text(sys.argv[1], "new", keep_backup=True)
    except OSError as exc:
        print(exc.strerror)
""")


@pytest.mark.skipif(sys.platform == "win32", reason="file size limits are POSIX rlimits")
def test_a_backup_that_cannot_be_written_leaves_the_earlier_backup_whole(
        tmp_path: Path) -> None:
    """The previous version was copied over the .bak in place: a write failing midway (a
    full disk) left a cut-off .bak, and the earlier one was gone."""
    target, bak = tmp_path / "session.json", tmp_path / "session.json.bak"
    target.write_text("x" * 5000)  # the file the new text replaces: too big to copy here
    bak.write_text("the earlier version")
    done = subprocess.run([sys.executable, "-c", BACKUP_FAILS, str(target)],
                          capture_output=True, text=True, check=True)
    assert done.stdout.strip() == os.strerror(27)  # EFBIG: the save failed
    assert target.read_text() == "x" * 5000
    assert bak.read_text() == "the earlier version"
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


#: a second process that starts writing ``argv[1]`` and stays inside the block
WRITER = textwrap.dedent("""
    import sys, time
    from speechcal_core.fsutil import staged_directory
    with staged_directory(sys.argv[1]) as staging:
        (staging / "frame.png").write_bytes(bytes(1000))
        print("writing", flush=True)
        time.sleep(120)
""")


@pytest.fixture
def writer(tmp_path: Path) -> Iterator[subprocess.Popen]:
    """A real process in the middle of writing ``tmp_path / "out"``; killed at the end."""
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(tmp_path / "out")],
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline() == "writing\n"
    yield proc
    proc.kill()
    proc.wait()


def _hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.mark.skipif(sys.platform == "win32", reason="folder locks are POSIX flock")
def test_a_killed_write_leaves_a_partial_folder_the_next_write_removes(
        tmp_path: Path, writer: subprocess.Popen) -> None:
    writer.send_signal(signal.SIGKILL)  # nothing of the process can clean up
    writer.wait()
    left = _hidden(tmp_path)
    assert len(left) == 1 and left[0].startswith(".out.partial-")
    (tmp_path / ".other.partial-x").mkdir()  # another output's staging is not ours to sweep
    with staged_directory(tmp_path / "out") as staging:
        (staging / "done.txt").write_text("x")
    assert _hidden(tmp_path) == [".other.partial-x"]
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["done.txt"]


@pytest.mark.skipif(sys.platform == "win32", reason="folder locks are POSIX flock")
def test_a_write_in_progress_keeps_its_partial_folder(tmp_path: Path,
                                                      writer: subprocess.Popen) -> None:
    theirs = _hidden(tmp_path)
    with staged_directory(tmp_path / "out") as staging:
        (staging / "done.txt").write_text("x")
    assert writer.poll() is None
    assert _hidden(tmp_path) == theirs
    assert (tmp_path / theirs[0] / "frame.png").stat().st_size == 1000


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


@pytest.mark.parametrize("name", ["e" * 255, "é" * 120 + "-export"])
def test_an_output_named_up_to_the_longest_name_is_written_and_replaced(
        tmp_path: Path, name: str) -> None:
    target = tmp_path / name  # 255 bytes: the hidden siblings' names must be shorter
    with staged_directory(target) as staging:
        (staging / "a.txt").write_text("first")
    with staged_directory(target, force=True) as staging:
        (staging / "b.txt").write_text("second")
    assert [p.name for p in target.iterdir()] == ["b.txt"]
    assert [p.name for p in tmp_path.iterdir()] == [name]  # nothing hidden left


def test_an_output_that_appears_while_writing_is_left_alone(tmp_path: Path) -> None:
    target = tmp_path / "out"
    with pytest.raises(SpeechCalError) as err, staged_directory(target) as staging:
        (staging / "a.txt").write_text("new")
        target.mkdir()  # another program, or a second export, writes there meanwhile
        (target / "notes.txt").write_text("theirs")
    assert [p.name for p in target.iterdir()] == ["notes.txt"]
    kept = tmp_path / "out-new"
    assert (kept / "a.txt").read_text() == "new"
    assert "appeared while" in str(err.value) and str(kept) in str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "out-new"]  # nothing hidden


def test_a_forced_replacement_is_checked_again_before_the_swap(tmp_path: Path) -> None:
    target = tmp_path / "out"
    target.mkdir()
    (tmp_path / "out-new").mkdir()  # taken: the output is kept at the next free name

    def may_replace(folder: Path) -> str:
        return "it holds notes" if (folder / "notes.txt").exists() else ""

    with pytest.raises(SpeechCalError, match="it holds notes"), \
            staged_directory(target, force=True, may_replace=may_replace) as staging:
        (staging / "a.txt").write_text("new")
        (target / "notes.txt").write_text("added while the export ran")
    assert (target / "notes.txt").exists()
    assert (tmp_path / "out-new-2" / "a.txt").read_text() == "new"
    with staged_directory(target / "inner", force=True, may_replace=may_replace) as staging:
        (staging / "b.txt").write_text("fine")  # nothing objects: replaced as before
    assert (target / "inner" / "b.txt").exists()


def test_the_current_folder_is_never_replaced(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    work = tmp_path / "work"
    (work / "inner").mkdir(parents=True)
    monkeypatch.chdir(work / "inner")
    for target in (Path("."), work, Path("..")):  # it, or a folder holding it
        with pytest.raises(SpeechCalError, match="current folder"), \
                staged_directory(target, force=True):
            pass
    assert (work / "inner").is_dir() and list(tmp_path.iterdir()) == [work]


def test_written_files_and_folders_get_ordinary_permissions(tmp_path: Path) -> None:
    with staged_directory(tmp_path / "out") as staging:
        atomic_write_text(staging / "a.json", "{}")
    mask = os.umask(0)
    os.umask(mask)
    assert (tmp_path / "out").stat().st_mode & 0o777 == 0o777 & ~mask
    assert (tmp_path / "out" / "a.json").stat().st_mode & 0o777 == 0o666 & ~mask


def _hidden(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _old_output(folder: Path) -> Path:
    """An earlier output folder ``out`` holding ``old.txt``."""
    target = folder / "out"
    target.mkdir()
    (target / "old.txt").write_text("old")
    return target


def test_force_replaces_an_existing_file_and_leaves_nothing_hidden(tmp_path: Path) -> None:
    target = tmp_path / "out.json"
    target.write_text("a file")
    with pytest.raises(OutputExistsError, match="--force"), staged_directory(target):
        pass
    assert target.read_text() == "a file"
    with staged_directory(target, force=True) as staging:
        (staging / "new.txt").write_text("x")
    assert sorted(p.name for p in target.iterdir()) == ["new.txt"]
    assert _hidden(tmp_path) == []


def test_force_replaces_a_link_not_what_it_points_to(tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "keep.txt").write_text("mine")
    target = tmp_path / "out"
    target.symlink_to(elsewhere, target_is_directory=True)
    with staged_directory(target, force=True) as staging:
        (staging / "new.txt").write_text("x")
    assert not target.is_symlink() and sorted(p.name for p in target.iterdir()) == ["new.txt"]
    assert (elsewhere / "keep.txt").read_text() == "mine"
    assert _hidden(tmp_path) == []


def test_an_old_folder_that_cannot_be_removed_is_reported(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    from speechcal_core.errors import SpeechCalError

    target = _old_output(tmp_path)

    def busy(path, *args, **kwargs) -> None:
        if kwargs.get("ignore_errors"):
            return
        raise OSError(16, "Device or resource busy", str(path))

    monkeypatch.setattr(shutil, "rmtree", busy)
    with pytest.raises(SpeechCalError, match="remove it") as exc, \
            staged_directory(target, force=True) as staging:
        (staging / "new.txt").write_text("x")
    left = _hidden(tmp_path)
    assert len(left) == 1 and left[0] in str(exc.value) and str(target) in str(exc.value)
    assert sorted(p.name for p in target.iterdir()) == ["new.txt"]


def test_a_failed_swap_puts_the_old_target_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from speechcal_core.errors import SpeechCalError

    target = _old_output(tmp_path)
    real_replace = os.replace

    def fail_into_place(src, dst) -> None:
        if Path(src).name.startswith(".out.partial-"):
            raise OSError(5, "Input/output error")
        real_replace(src, dst)

    monkeypatch.setattr(os, "replace", fail_into_place)
    with pytest.raises(SpeechCalError, match=str(target)), \
            staged_directory(target, force=True) as staging:
        (staging / "new.txt").write_text("x")
    assert sorted(p.name for p in target.iterdir()) == ["old.txt"]
    assert _hidden(tmp_path) == []


def test_folder_write_problem_says_what_stops_a_write_and_leaves_nothing(tmp_path: Path) -> None:
    assert folder_write_problem(tmp_path) is None
    assert list(tmp_path.iterdir()) == []
    gone = tmp_path / "gone"
    assert folder_write_problem(gone) == f"the folder {gone} does not exist"
    (tmp_path / "f").write_text("x")
    assert folder_write_problem(tmp_path / "f") == f"{tmp_path / 'f'} is a file, not a folder"


@pytest.mark.parametrize("depth", [1, 2])
def test_staged_directory_under_a_file_names_the_file(tmp_path: Path, depth: int) -> None:
    blocking = tmp_path / "notes.txt"
    blocking.write_text("mine")
    target = blocking / "sub" / "export" if depth == 2 else blocking / "export"
    with pytest.raises(SpeechCalError, match=f"{blocking} is a file, not a folder"), \
            staged_directory(target):
        pass
    assert blocking.read_text() == "mine"


def test_a_folder_under_a_file_is_reported_as_the_file(tmp_path: Path) -> None:
    blocking = tmp_path / "notes.txt"
    blocking.write_text("mine")
    assert folder_write_problem(blocking / "sessions") == f"{blocking} is a file, not a folder"
    assert folder_write_problem(blocking) == f"{blocking} is a file, not a folder"
    assert folder_write_problem(tmp_path / "missing") == \
        f"the folder {tmp_path / 'missing'} does not exist"


def test_overlap_names_what_an_output_would_touch(tmp_path: Path) -> None:
    bag2 = tmp_path / "rec"  # a ROS2 bag folder
    bag2.mkdir()
    (bag2 / "metadata.yaml").write_text("rosbag2_bagfile_information: {}")
    audio = tmp_path / "mic.ogg"
    audio.write_bytes(b"OggS")
    inputs = {"recording": [bag2], "audio": [audio]}
    assert overlap(bag2 / "metadata.yaml", inputs) == ("inside", "recording", bag2)
    assert overlap(tmp_path / "x" / ".." / "mic.ogg", inputs) == ("is", "audio", audio)
    assert overlap(tmp_path, inputs) == ("holds", "recording", bag2)
    assert overlap(tmp_path / "session.json", inputs) is None
    link = tmp_path / "link.ogg"
    link.symlink_to(audio)
    assert overlap(link, inputs) is None  # replacing the link leaves the audio
    assert overlap(tmp_path, {"audio": [link]}) == ("holds", "audio", link)
