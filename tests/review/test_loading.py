"""Opening a recording for review: where its new session goes, and what an existing one
means for the audio given."""

from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

import pytest

from speechcal_core.errors import UsageError
from speechcal_core.review.loading import default_session_path, load_for_review
from speechcal_core.session.store import SessionFileError, load_session, save_session


def _copy_of(tiny_synth: tuple[Path, dict], tmp_path: Path) -> tuple[str, str]:
    """The tiny session's recording and audio, copied so each test has its own folder."""
    folder, truth = tiny_synth
    out = tmp_path / "rec"
    shutil.copytree(folder, out)
    return str(out / truth["recording"]), str(out / truth["audio"])


def _with_its_session(processed_tiny, tiny_synth: tuple[Path, dict], tmp_path: Path,
                      where: str | None = None) -> tuple[str, str]:
    """As :func:`_copy_of`, with the session a first review of them made at ``where``
    (relative to ``tmp_path``; default: beside the recording)."""
    _folder, truth = tiny_synth
    shutil.copytree(processed_tiny(where), tmp_path, dirs_exist_ok=True)
    out = tmp_path / "rec"
    return str(out / truth["recording"]), str(out / truth["audio"])


def test_a_new_session_goes_where_asked(tiny_synth, tmp_path: Path) -> None:
    recording, audio = _copy_of(tiny_synth, tmp_path)
    target = tmp_path / "elsewhere" / "mine.json"
    target.parent.mkdir()
    inputs = load_for_review(recording=[recording], audio=audio, new_session_path=target)
    inputs.close()
    assert inputs.session_path == target and target.exists()
    assert not default_session_path([recording]).exists()
    assert load_session(target).sets


def test_an_unwritable_session_folder_fails_before_processing_and_says_what_to_do(
        tiny_synth, tmp_path: Path) -> None:
    recording, audio = _copy_of(tiny_synth, tmp_path)
    target = tmp_path / "missing" / "session.json"
    steps: list[str] = []
    with pytest.raises(SessionFileError, match="--session PATH"):
        load_for_review(recording=[recording], audio=audio, new_session_path=target,
                        progress=lambda text, _f: steps.append(text))
    assert not any("clap" in s or "frames" in s for s in steps)  # nothing was processed


def test_an_existing_session_with_other_audio_is_opened_with_a_note(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    other = Path(tmp_path / "other.ogg")
    shutil.copy(audio, other)
    inputs = load_for_review(recording=[recording], audio=str(other))
    inputs.close()
    # nothing decided yet: "review work kept" would promise what is not there
    assert "(nothing decided in it yet)" in inputs.note
    assert f"not {other}" in inputs.note and Path(inputs.session.audio) == Path(audio)
    again = load_for_review(recording=[recording], audio=audio)
    again.close()
    assert "not " not in again.note.split("kept")[-1]  # the same audio: no warning


def test_a_given_session_of_another_recording_is_opened_with_a_note(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path,
                                         "reviews/lab.json")
    target = tmp_path / "reviews" / "lab.json"
    other = tmp_path / "other.bag"
    shutil.copy(recording, other)
    inputs = load_for_review(recording=[str(other)], audio=audio, new_session_path=target)
    inputs.close()
    assert f"it is the session of {recording}, not of {other}" in inputs.note


def _open_files() -> set[str]:
    fds = Path("/proc/self/fd")
    out = set()
    for fd in fds.iterdir():
        with contextlib.suppress(OSError):  # the listing's own descriptor is gone
            out.add(str(fd.readlink()))
    return out


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc")
@pytest.mark.parametrize("step", ["reading audio", "ready"])
def test_a_cancel_late_in_opening_closes_the_recording(processed_tiny, tiny_synth,
                                                       tmp_path: Path, step: str) -> None:
    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)

    class Cancelled(Exception):
        pass

    def progress(text: str, _fraction: float) -> None:
        if text == step:
            raise Cancelled

    with pytest.raises(Cancelled):
        load_for_review(recording=[recording], audio=audio, progress=progress)
    assert not any(p.startswith(str(Path(recording).parent)) for p in _open_files())


def test_a_moved_recording_says_how_to_keep_the_decisions(processed_tiny, tiny_synth,
                                                          tmp_path: Path) -> None:
    recording, _audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    session_path = default_session_path([recording])
    moved = tmp_path / "moved" / Path(recording).name
    moved.parent.mkdir()
    shutil.move(recording, moved)
    with pytest.raises(SessionFileError) as exc:
        load_for_review(session_path=session_path)
    text = str(exc.value)
    assert text.startswith(f"{session_path}: its recording") and "is missing" in text
    assert "keep the review decisions" in text
    assert f"speechcal review RECORDING --audio AUDIO --session {session_path})" in text


def test_a_moved_recording_given_with_the_session_is_followed_and_the_review_kept(
        moved_session) -> None:
    session_path, moved, bag, audio = moved_session
    new_recording, new_audio = moved / bag, moved / audio
    roundabout = moved.parent / ".." / moved.parent.name / moved.name  # as typed
    inputs = load_for_review(recording=[str(roundabout / bag)], audio=str(roundabout / audio),
                             new_session_path=session_path)
    inputs.close()
    assert "(1 decision kept)" in inputs.note and "its recording moved from" in inputs.note
    assert f"now read from {moved}" in inputs.note and "not of" not in inputs.note
    # the paths are said and kept plainly, not as the session file's ../rec
    assert f"moved from {session_path.parent.parent / 'rec'} and" in inputs.note
    assert ".." not in inputs.note
    saved = load_session(session_path)
    assert [Path(p).resolve() for p in saved.recording] == [new_recording]
    assert Path(saved.audio).resolve() == new_audio and saved.sets[0].decision == "accepted"
    assert ".." not in Path(saved.audio).parts


def test_another_recording_of_the_same_name_is_not_taken_for_the_moved_one(
        processed_tiny, tiny_synth, snapshot_synth, tmp_path: Path) -> None:
    """Every take is recording.bag: the session's own gone, another take of that name
    was taken for it, saved, and shown with the old decisions on other frames."""
    from speechcal_core.errors import UsageError

    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path,
                                         "reviews/lab.json")
    session_path = tmp_path / "reviews" / "lab.json"
    shutil.rmtree(Path(recording).parent)
    folder, truth = snapshot_synth
    other = tmp_path / "other"
    shutil.copytree(folder, other)
    assert Path(recording).name == truth["recording"] and Path(audio).name == truth["audio"]
    before = session_path.read_text()
    with pytest.raises(UsageError) as refused:
        load_for_review(recording=[str(other / truth["recording"])],
                        audio=str(other / truth["audio"]), new_session_path=session_path)
    assert "is not the recording this session was made from, though its name is the same (" \
        in str(refused.value)
    assert "process this one into another session file (--session)" in str(refused.value)
    assert session_path.read_text() == before


def _moved_with_other_audio(processed_tiny, tiny_synth, tmp_path: Path, keep_share: float
                            ) -> tuple[Path, Path, Path]:
    """A session made from a recording and its audio, then the folder moved with the
    audio replaced by another take of the same name (its first ``keep_share``): the
    session file, the moved recording and the other audio."""
    import soundfile as sf

    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path,
                                         "reviews/lab.json")
    session_path = tmp_path / "reviews" / "lab.json"
    moved = tmp_path / "archive" / "rec"
    shutil.move(str(Path(recording).parent), moved)
    other = moved / Path(audio).name
    samples, rate = sf.read(other)
    sf.write(other, samples[: int(len(samples) * keep_share)], rate)
    return session_path, moved / Path(recording).name, other


def test_another_take_of_the_audio_is_not_taken_for_the_moved_one(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    """Every take's audio may be mic.wav: relinking took any file of that name."""
    from speechcal_core.audio.identity import AUDIO_FILE_KEY
    from speechcal_core.errors import UsageError

    session_path, recording, other = _moved_with_other_audio(processed_tiny, tiny_synth, tmp_path,
                                                             0.995)
    assert load_session(session_path).extra[AUDIO_FILE_KEY]["channels"] == 1
    before = session_path.read_text()
    with pytest.raises(UsageError) as refused:
        load_for_review(recording=[str(recording)], audio=str(other),
                        new_session_path=session_path)
    text = str(refused.value)
    assert text.startswith(f"{other} is not the audio this session was made from, though "
                           "its name is the same (it lasts ")
    assert "the session's audio" in text and "give the session's own audio" in text
    assert session_path.read_text() == before


def test_a_session_without_the_audio_record_checks_the_length_against_its_words(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    """Sessions saved before the audio's record was kept: an audio too short for the
    session's trigger words is another take."""
    from speechcal_core.audio.identity import AUDIO_FILE_KEY
    from speechcal_core.errors import UsageError

    session_path, recording, other = _moved_with_other_audio(processed_tiny, tiny_synth, tmp_path,
                                                             0.5)
    old = load_session(session_path)
    del old.extra[AUDIO_FILE_KEY]
    save_session(old, session_path)
    with pytest.raises(UsageError, match=r"it lasts [\d.]+ s, but the session's words run to"):
        load_for_review(recording=[str(recording)], audio=str(other),
                        new_session_path=session_path)


def test_an_existing_session_keeps_its_trigger_words_and_says_so(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    from speechcal_core.speech.matching import TriggerSpec

    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    inputs = load_for_review(recording=[recording], audio=audio,
                             triggers=TriggerSpec(("snapshot",)), channel=0)
    inputs.close()
    assert inputs.session.triggers_word == ["capture"]
    assert ("not processed again with trigger word snapshot (it has capture) and audio "
            "channel 0 (it has all channels mixed)") in inputs.note
    same = load_for_review(recording=[recording], audio=audio, triggers=TriggerSpec())
    same.close()
    assert "again" not in same.note
    other_word = load_for_review(recording=[recording], audio=audio,
                                 triggers=TriggerSpec(("snapshot",)))
    other_word.close()
    assert ("not detected again with trigger word snapshot (it has capture): Edit ▸ Find "
            "trigger words… (Ctrl+F) adds its sets and keeps the review work") in other_word.note
    other_word.session.triggers_word = ["snapshot", "capture"]  # found with Ctrl+F since
    save_session(other_word.session, other_word.session_path)
    again = load_for_review(recording=[recording], audio=audio,
                            triggers=TriggerSpec(("snapshot",)))
    again.close()
    assert "detected again" not in again.note
    finer = load_for_review(recording=[recording], audio=audio,
                            triggers=TriggerSpec(("capture",), sensitivity=0.9))
    finer.close()
    assert ("not detected again with sensitivity 0.9 (it has 0.5): Edit ▸ Find trigger "
            "words… (Ctrl+F)") in finer.note


def test_a_new_session_looks_for_the_board_given_and_an_existing_one_says_it_keeps_its_own(
        checkerboard_synth, tmp_path: Path) -> None:
    """review RECORDING --target: a checkerboard operator gets corners from the start, not
    after processing again into a new session (review work lost)."""
    from speechcal_core.target import TargetSpec

    recording, audio = _copy_of(checkerboard_synth, tmp_path)
    board = TargetSpec.from_kalibr_yaml(Path(recording).parent / "target.yaml")
    assert board.kind == "checkerboard"
    inputs = load_for_review(recording=[recording], audio=audio, target=board)
    inputs.close()
    assert TargetSpec.from_stored(inputs.session.extra["target"]) == board
    assert inputs.session.extra["target_assumed"] is False
    again = load_for_review(recording=[recording], audio=audio, target=TargetSpec())
    again.close()
    assert TargetSpec.from_stored(again.session.extra["target"]) == board
    assert (f"not processed again with the board {TargetSpec().describe()} (it has "
            f"{board.describe()}): move {again.session_path.name} away") in again.note
    same = load_for_review(recording=[recording], audio=audio, target=board)
    same.close()
    assert "again" not in same.note


def test_a_new_session_uses_the_streams_chosen_and_an_existing_one_leaves_more_out(
        tiny_synth, tmp_path: Path) -> None:
    from speechcal_core.sources import StreamChoice

    recording, audio = _copy_of(tiny_synth, tmp_path)
    two = StreamChoice(skip=("/cam2/image_raw",))
    inputs = load_for_review(recording=[recording], audio=audio, streams=two)
    inputs.close()
    assert [s.name for s in inputs.source.streams] == ["/cam0/image_raw", "/cam1/image_raw"]
    assert inputs.session.extra["streams"] == ["/cam0/image_raw", "/cam1/image_raw"]
    session = load_session(inputs.session_path)
    decided = session.sets[0].id
    session.replace_set(session.sets[0].with_decision("rejected"))
    save_session(session, inputs.session_path)
    reopened = load_for_review(session_path=inputs.session_path)
    reopened.close()
    assert [s.name for s in reopened.source.streams] == ["/cam0/image_raw", "/cam1/image_raw"]
    same = load_for_review(recording=[recording], audio=audio, streams=two)
    same.close()
    assert "left out" not in same.note
    # one more left out of the session made: its review work stays
    one = load_for_review(recording=[recording], audio=audio,
                          streams=StreamChoice(skip=("/cam1/image_raw",)))
    one.close()
    assert ("left out /cam1/image_raw (its frames, calibration and coverage; the review work "
            "is kept)") in one.note
    assert [s.name for s in one.source.streams] == ["/cam0/image_raw"]
    kept = load_session(one.session_path)
    assert kept.extra["streams"] == ["/cam0/image_raw"]
    assert kept.set_by_id(decided).decision == "rejected"
    assert {f.stream for s in kept.sets for f in s.frames} == {"/cam0/image_raw"}
    assert set(kept.calibration) <= {"/cam0/image_raw"}
    assert set(kept.extra["coverage"]) <= {"/cam0/image_raw"}
    # a stream the session does not use needs processing anew
    with pytest.raises(UsageError, match="it can leave some of them out but take in no "
                                         "other"):
        load_for_review(session_path=one.session_path,
                        streams=StreamChoice(only=("/cam2/image_raw",)))


def test_a_session_whose_audio_was_replaced_in_place_opens_with_a_note(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    import soundfile as sf

    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    session_path = default_session_path([recording])
    inputs = load_for_review(session_path=session_path)
    inputs.close()
    assert "not the audio" not in inputs.note
    samples, rate = sf.read(audio)
    sf.write(audio, samples[: len(samples) // 2], rate)
    inputs = load_for_review(session_path=session_path)
    inputs.close()
    assert f"{Path(audio).absolute()} is not the audio this session was made from (it lasts " \
        in inputs.note
    assert "put the session's own audio back there" in inputs.note


def test_an_existing_session_opens_without_the_audio_given(processed_tiny, tiny_synth,
                                                           tmp_path: Path) -> None:
    """The session knows its audio; a new one cannot do without it."""
    recording, audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    inputs = load_for_review(recording=[recording])
    inputs.close()
    assert "nothing decided in it yet" in inputs.note
    assert "not " not in inputs.note.split("yet")[-1]
    assert Path(inputs.session.audio) == Path(audio)
    with pytest.raises(UsageError, match="a recording needs its audio file: pass --audio"):
        load_for_review(recording=[recording], new_session_path=tmp_path / "new.json")


def test_review_work_in_the_bak_of_an_undecided_session_is_set_aside_before_saving(
        processed_tiny, tiny_synth, tmp_path: Path) -> None:
    """``process --force`` keeps the reviewed file as .bak beside its fresh, undecided
    session; the window's first save kept that undecided file as .bak over it, and the
    decisions were gone."""
    _with_its_session(processed_tiny, tiny_synth, tmp_path, "reviews/lab.json")
    path = tmp_path / "reviews" / "lab.json"
    reviewed = load_session(path)
    reviewed.sets[:2] = [s.with_decision("accepted") for s in reviewed.sets[:2]]
    bak = path.parent / "lab.json.bak"
    save_session(reviewed, bak, backup=False)  # as process --force leaves it
    (path.parent / "lab.json.bak.1").write_text("an older one, left alone")
    inputs = load_for_review(session_path=path)
    inputs.close()
    assert ("lab.json.bak holds review work (2 decisions) and lab.json none: it is kept as "
            "lab.json.bak.2") in inputs.note
    inputs.session.sets[0] = inputs.session.sets[0].with_decision("rejected")
    save_session(inputs.session, path)  # the window's autosave
    kept = load_session(path.parent / "lab.json.bak.2")
    assert [s.decision for s in kept.sets[:2]] == ["accepted", "accepted"]
    assert (path.parent / "lab.json.bak.1").read_text() == "an older one, left alone"
    # a session holding review work of its own keeps the .bak as the previous version
    again = load_for_review(session_path=path)
    again.close()
    assert "kept as" not in again.note and bak.exists()
    assert not (path.parent / "lab.json.bak.3").exists()


def test_another_take_put_in_place_of_the_recording_is_refused_not_reviewed(
        processed_tiny, tiny_synth, snapshot_synth, tmp_path: Path) -> None:
    """Every take is recording.bag: a new take copied over the old one, then the old
    session opened. The window showed the new take's frames under the old sets (by
    index), for decisions on frames the session does not hold, where ``export`` refuses
    the session ("has no frame stamped ..."). Opening now says so, as export does, and
    leaves the session file as it was."""
    recording, _audio = _with_its_session(processed_tiny, tiny_synth, tmp_path)
    session_path = default_session_path([recording])
    folder, truth = snapshot_synth
    assert Path(recording).name == truth["recording"]
    shutil.copy(folder / truth["recording"], recording)
    before = session_path.read_bytes()
    with pytest.raises(SessionFileError) as refused:
        load_for_review(session_path=session_path)
    text = str(refused.value)
    assert text.startswith(f"{session_path}: its recording {recording} is not the one this "
                           "session was made from (")
    assert "has no frame stamped" in text and "\n" not in text
    assert "put the session's own recording back there" in text
    assert session_path.read_bytes() == before


@pytest.mark.parametrize("opened", ["lab.json.bak", "lab.json.bak.3"])
def test_a_kept_previous_version_opened_is_restored_by_its_first_save(
        processed_tiny, tiny_synth, tmp_path: Path, opened: str) -> None:
    """Its review work was saved beside it as lab.json.bak.bak. The session's file is
    lab.json: opening changes nothing, the first save writes lab.json and keeps the
    lab.json it replaces as a free .bak.N (the .bak may be the version opened)."""
    _with_its_session(processed_tiny, tiny_synth, tmp_path, "reviews/lab.json")
    path = tmp_path / "reviews" / "lab.json"
    older = load_session(path)
    older.sets[0] = older.sets[0].with_decision("rejected")
    save_session(older, path.with_name(opened), backup=False)
    current = path.read_bytes()
    inputs = load_for_review(session_path=path.with_name(opened))
    inputs.close()
    assert (inputs.session_path, inputs.restores) == (path, path.with_name(opened))
    assert inputs.note.startswith(f"{opened} is a kept previous version: review work saved "
                                  "restores it as lab.json; the lab.json there now is then "
                                  "kept as lab.json.bak.1")
    assert path.read_bytes() == current  # opened only
    aside = save_session(inputs.session, inputs.session_path, expect=inputs.session_stamp,
                         keep_aside=True)
    assert aside == path.with_name("lab.json.bak.1") and aside.read_bytes() == current
    assert load_session(path).sets[0].decision == "rejected"
    assert not path.with_name(f"{opened}.bak").exists()
    assert not (path.with_name("lab.json.bak").exists() and opened != "lab.json.bak")
