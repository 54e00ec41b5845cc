"""``speechcal export`` never writes over what the session reads, nor with --force a file."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from export_sessions import accepted_sets_over, write_session

from speechcal_core.cli import main
from speechcal_core.export import ExportError, export_frame_sets, export_session_file
from speechcal_core.session.store import load_session
from speechcal_core.sources import open_recording


def _run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(["export", *args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _tree(folder: Path) -> dict[str, bytes | None]:
    """Every path under ``folder`` with its bytes (None for a folder)."""
    return {str(p.relative_to(folder)): None if p.is_dir() else p.read_bytes()
            for p in sorted(folder.rglob("*"))}


@pytest.fixture
def own_session(small_recording, tmp_path: Path) -> Path:
    """``c1/session.json`` beside its own copy of the recording and ``audio.ogg`` (as
    ``speechcal synth`` and ``process`` leave them), safe to damage."""
    folder, truth = small_recording("ros1", "jpeg")
    c1 = tmp_path / "c1"
    shutil.copytree(folder, c1)
    return write_session(c1, truth, c1 / "session.json")


def _outs(session: Path) -> dict[str, Callable[[], Path]]:
    c1 = session.parent
    return {
        "audio": lambda: Path(load_session(session).audio or ""),
        "session file": lambda: session,
        "recording": lambda: Path(load_session(session).recording[0]),
        "session folder": lambda: c1,
        "folder above": lambda: c1.parent,
        "recording via ..": lambda: c1 / ".." / c1.name / Path(
            load_session(session).recording[0]).relative_to(c1),
    }


@pytest.mark.parametrize("which", ["audio", "session file", "recording", "session folder",
                                   "folder above", "recording via .."])
def test_no_input_of_the_session_is_an_output_even_with_force(
    own_session: Path, capsys, which: str
) -> None:
    out = _outs(own_session)[which]()
    assert out.exists()
    before = _tree(own_session.parent)
    code, stdout, err = _run(capsys, str(own_session), "--format", "kalibr", "--out", str(out),
                             "--include-undecided", "--force")
    assert code == 1 and stdout == "" and err.count("\n") == 1
    assert "choose another output folder" in err
    assert _tree(own_session.parent) == before


def test_refusal_names_the_input_it_protects(own_session: Path, capsys) -> None:
    audio = Path(load_session(own_session).audio or "")
    code, _out, err = _run(capsys, str(own_session), "--format", "kalibr", "--out", str(audio),
                           "--force")
    assert code == 1 and str(audio) in err and "audio" in err
    assert audio.is_file()
    code, _out, err = _run(capsys, str(own_session), "--format", "kalibr", "--out",
                           str(own_session), "--force")
    assert code == 1 and f"this is the session file {own_session}, which the export" in err


def test_the_audio_is_protected_through_a_linked_folder(own_session: Path, capsys) -> None:
    link = own_session.parent.parent / "link"
    link.symlink_to(own_session.parent, target_is_directory=True)
    audio = own_session.parent / "audio.ogg"
    data = audio.read_bytes()
    code, _out, err = _run(capsys, str(own_session), "--format", "folders", "--out",
                           str(link / "audio.ogg"), "--force")
    assert code == 1 and "choose another output folder" in err
    assert audio.read_bytes() == data


def test_a_camera_folder_inside_an_image_folder_recording_is_never_an_output(
    session_file, tmp_path: Path
) -> None:
    kalibr = tmp_path / "kalibr"
    export_session_file(session_file(), "kalibr", kalibr)
    before = _tree(kalibr)
    with open_recording([kalibr]) as source:
        session = accepted_sets_over(source, ["cam0", "cam1"])
        with pytest.raises(ExportError, match="choose another output folder"):
            export_frame_sets(session, source, "folders", kalibr / "cam1", force=True)
    assert _tree(kalibr) == before


def test_force_never_replaces_a_file_and_leaves_nothing_hidden(own_session: Path,
                                                               capsys) -> None:
    c1 = own_session.parent
    truth = c1 / "truth.json"
    kept = truth.read_bytes()
    code, _out, err = _run(capsys, str(own_session), "--format", "kalibr", "--out", str(truth),
                           "--include-undecided")
    assert code == 1 and str(truth) in err and "this is a file, not an export folder" in err
    assert "--force" not in err and truth.is_file()  # it would not help
    code, _out, err = _run(capsys, str(own_session), "--format", "kalibr", "--out",
                           str(truth), "--include-undecided", "--force")
    assert code == 1 and "this is a file, not an export folder" in err
    assert truth.read_bytes() == kept
    assert [p.name for p in c1.iterdir() if p.name.startswith(".truth.json")] == []
