"""Edit ▸ Undo / Redo: named after the step they revert, off when there is none, and the
same steps as U and the keys."""

from __future__ import annotations

from PySide6.QtCore import Qt


def _texts(window) -> tuple[str, str]:
    return window.undo_action.text(), window.redo_action.text()


def test_undo_and_redo_entries_name_the_step_and_follow_the_keys(qtbot, window) -> None:
    model = window.model
    assert window.edit_menu.title() == "&Edit"
    assert _texts(window) == ("&Undo", "&Redo")
    assert not window.undo_action.isEnabled() and not window.redo_action.isEnabled()
    assert not window.undo_button.isEnabled()  # the [U] button under the list agrees
    first = model.current_set.id
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.waitUntil(lambda: window.undo_action.isEnabled())
    assert _texts(window) == (f"&Undo decision on set {first}", "&Redo")
    assert window.undo_button.isEnabled()
    assert window.undo_button.toolTip() == f"Undo decision on set {first}"
    window.undo_action.trigger()  # as the menu entry or Ctrl+Z
    assert model.current_set.decision == "undecided"
    qtbot.waitUntil(lambda: window.redo_action.isEnabled())
    assert _texts(window) == ("&Undo", f"&Redo decision on set {first}")
    window.redo_action.trigger()
    assert model.current_set.decision == "accepted"
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # audio 1 ms later
    qtbot.waitUntil(lambda: window.undo_action.text() == "&Undo audio offset change")
    qtbot.keyClick(window, Qt.Key.Key_U)
    qtbot.waitUntil(lambda: window.redo_action.text() == "&Redo audio offset change")
    assert window.undo_action.text() == f"&Undo decision on set {first}"


def test_the_shortcuts_belong_to_the_menu_entries(qtbot, window) -> None:
    assert window.undo_action.shortcut().toString() == "Ctrl+Z"
    assert [k.toString() for k in window.redo_action.shortcuts()] == ["Ctrl+Shift+Z", "Ctrl+Y"]
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_R)
    qtbot.waitUntil(window.undo_action.isEnabled)
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert model.current_set.decision == "undecided"  # the menu closed, the key works
    qtbot.waitUntil(window.redo_action.isEnabled)
    qtbot.keyClick(window, Qt.Key.Key_Z,
                   Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert model.current_set.decision == "rejected"
