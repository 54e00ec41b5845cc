"""Find more like this in the window: T on a missed trigger, then S, and the rows of the
other triggers of that voice appear, undecided, found off the UI thread."""

from __future__ import annotations

from PySide6.QtCore import Qt
from truth_sessions import quiet_time_s

from speechcal_core.review.similar import SIMILAR_SOURCE


def test_s_on_an_added_set_adds_rows_for_words_like_it(qtbot, open_window,
                                                      missed_voice_file) -> None:
    path, missed = missed_voice_file
    window = open_window(path)
    model = window.model
    model.set_playhead(missed[0]["session_ns"])
    qtbot.keyClick(window, Qt.Key.Key_T)
    marked = model.current_set
    rows = window.table.model().rowCount()
    qtbot.keyClick(window, Qt.Key.Key_S)
    assert window.status.running("similar")
    # the added set may still be re-scoring: the status line shows both jobs side by side
    assert f"finding more like set {marked.id}" in window.status_text.text()
    qtbot.waitUntil(lambda: window.table.model().rowCount() > rows, timeout=30_000)

    new = [s for s in model.session.sets if s.trigger.source == SIMILAR_SOURCE]
    assert len(new) == window.table.model().rowCount() - rows >= 2
    assert all(s.decision == "undecided" for s in new)
    assert model.current_set.id == marked.id  # still current (perhaps re-scored meanwhile)
    assert f"found {len(new)} more like set {marked.id}" in window.status_text.text()
    assert not window.similar.busy()
    qtbot.keyClick(window, Qt.Key.Key_U)  # one undo takes them all back
    assert window.table.model().rowCount() == rows


def test_s_without_speech_near_the_set_says_so(qtbot, open_window, missed_voice_file,
                                               noisy_synth) -> None:
    window = open_window(missed_voice_file[0])
    model = window.model
    model.set_playhead(int(model.session.sync.to_session(quiet_time_s(noisy_synth[1]))))
    qtbot.keyClick(window, Qt.Key.Key_T)
    rows = window.table.model().rowCount()
    qtbot.keyClick(window, Qt.Key.Key_S)
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    assert "no speech near" in window.status_text.text()
    assert window.table.model().rowCount() == rows


def test_a_set_removed_while_its_search_runs_gets_nothing_added(
        qtbot, open_window, missed_voice_file, monkeypatch) -> None:
    """Del on a false trigger while S searches from it: words like a false trigger are
    not wanted, and the result must not name a set that is gone."""
    import threading

    from speechcal_core.review.similar import SimilarRequest

    gate = threading.Event()
    run = SimilarRequest.run

    def gated(self, audio, progress=None):
        gate.wait(30)
        return run(self, audio, progress)

    monkeypatch.setattr(SimilarRequest, "run", gated)
    path, missed = missed_voice_file
    window = open_window(path)
    model = window.model
    model.set_playhead(missed[0]["session_ns"])
    qtbot.keyClick(window, Qt.Key.Key_T)
    marked = model.current_set.id
    qtbot.keyClick(window, Qt.Key.Key_S)
    qtbot.keyClick(window, Qt.Key.Key_Delete)
    assert all(s.id != marked for s in model.session.sets)
    rows = window.table.model().rowCount()
    gate.set()
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    assert window.table.model().rowCount() == rows
    assert f"set #{marked} was removed while its search ran" in window.status_text.text()
