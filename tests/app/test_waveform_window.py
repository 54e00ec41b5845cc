"""The waveform in the window: an audio file moved during the session is named on the
status line, once, with what to do."""

from __future__ import annotations

import shutil
from pathlib import Path

from truth_sessions import truth_session

from speechcal_core.session.store import save_session


def test_moved_audio_file_is_named_once_on_the_status_line(open_window, tiny_synth,
                                                          tmp_path: Path) -> None:
    folder, truth = tiny_synth
    copy = tmp_path / "session"
    shutil.copytree(folder, copy)  # the shared session's audio stays where it is
    session = truth_session(copy, truth)
    session.sync_evidence = {"claps": truth["claps"]}
    save_session(session, tmp_path / "review.json")
    window = open_window(tmp_path / "review.json")
    waveform = window.waveform
    audio = waveform.pyramid.source.path
    assert str(copy) in str(audio)
    window.status.say("")
    audio.rename(audio.with_name("moved-" + audio.name))
    x0, x1 = waveform.getViewBox().viewRange()[0]
    x0 = (x0 + x1) / 2  # within the audio
    waveform.setXRange(x0, x0 + 0.05, padding=0)  # raw samples: read from the file
    assert waveform.pyramid.unreadable
    text = window.status_text.text()
    assert str(audio) in text and "coarse levels only" in text
    assert "put it back" in text and "reopen the session" in text
    window.status.end("waveform")  # the operator read it
    waveform.setXRange(x0 - 1.0, x0 - 0.95, padding=0)
    waveform.setXRange(x0 + 0.5, x0 + 1.0, padding=0)
    assert "coarse levels" not in window.status_text.text()  # said once only
