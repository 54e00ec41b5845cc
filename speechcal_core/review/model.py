"""The review model: playhead, current frame set, decisions with undo, autosave hooks.

Plain Python with callbacks; the Qt window connects them to widgets. Every keyboard
action is a named method here, so tests drive the review without a window.

Offset edits and added sets show the frames nearest each trigger at once; the best-still
search runs elsewhere (it takes about 0.1 s per set): :meth:`ReviewModel.rescore_request`
says what to re-score, :meth:`ReviewModel.apply_rescored` takes the results unless they
are stale. Coverage and the calibration check follow the chosen frames and decisions the
same way (:meth:`ReviewModel.checks_request`, :meth:`ReviewModel.apply_checks`), and
"find more like this" searches the audio elsewhere too (:meth:`ReviewModel.similar_request`,
:meth:`ReviewModel.apply_similar`).
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from speechcal_core.frames.nearest import frame_period_ns, nearest_choice, nearest_choices
from speechcal_core.frames.word_stillness import WordStillness, word_stillness
from speechcal_core.review.checks import (
    ChecksRequest,
    ChecksResult,
    apply_checks,
    checks_due,
    checks_request,
    still_wanted,
    stream_sizes,
)
from speechcal_core.review.detect_again import (
    DetectResult,
    record_settings,
    restore_settings,
    settings_of,
)
from speechcal_core.review.rescore import (
    RescoreRequest,
    RescoreResult,
    apply_rescore,
    export_waits_for,
    needs_rescore,
    rescore_ids,
    rescore_request,
)
from speechcal_core.review.similar import (
    SIMILAR_SOURCE,
    SimilarRequest,
    SimilarResult,
    similar_request,
)
from speechcal_core.review.summary import FILTERS, shown_indices
from speechcal_core.review.undo_history import UNDO_HISTORY_KEY, HistoryWriter, read_history
from speechcal_core.review.undo_steps import (
    Added,
    AddedMany,
    Decided,
    EarlierOffsetChange,
    OffsetChanged,
    Removed,
    RemovedMany,
    UndoStep,
    step_label,
)
from speechcal_core.session.model import (
    FRAMES_BEFORE_EDIT_KEY,
    REVIEW_PLACE_KEY,
    FrameChoice,
    FrameSet,
    Session,
    Trigger,
)
from speechcal_core.sync.model import SyncModel

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource

#: what the session keeps of its sets' figures for the sync they were measured for: the
#: corners and details per set, and per camera what sharpness and stillness were judged
#: against; an offset edit's undo puts them back with the frames
MEASURED_FOR_SYNC = ("frame_details", "frame_references")

EVENTS = ("playhead", "current_set", "decision", "sets", "sync", "saved", "filter",
          "rescored", "checks", "similar")

#: the nearest-frame choices an offset edit keeps for the next one, per stream: at most
#: this many per set (a held ``]`` picks each set's next frames every few steps)
NEAREST_KNOWN_PER_SET = 8

#: ``Trigger.source`` of a trigger the operator added in review (kept in the session file)
OPERATOR_SOURCE = "manual"
#: adding a set is refused (the existing one is selected) this close to another set
ADD_MIN_GAP_NS = 200_000_000

#: why A, R or Del did nothing (``verb``: "decide on", "remove"): no set is left
NO_SETS_LEFT = "no frame sets to {verb}: T adds one at the playhead"
#: key name -> action method name (the window only maps key presses to these)
KEY_BINDINGS: dict[str, str] = {
    "A": "accept",
    "R": "reject",
    "U": "undo",
    "Ctrl+Z": "undo",
    "Ctrl+Shift+Z": "redo",
    "K": "next_set",
    "J": "previous_set",
    "Right": "next_frame",
    "Left": "previous_frame",
    "Shift+Right": "next_frame_of_every_camera",
    "Shift+Left": "previous_frame_of_every_camera",
    "Home": "first_set",
    "End": "last_set",
    "F": "next_filter",
    "T": "add_set",
    "Delete": "remove_set",
    "S": "find_similar",
    "[": "offset_minus_ms",
    "]": "offset_plus_ms",
    "{": "offset_minus_frame",
    "}": "offset_plus_frame",
    "C": "clap_at_playhead",
}


@dataclass(frozen=True)
class TileState:
    """What one camera tile shows at the playhead."""

    stream: str
    index: int  # -1: no frame near the playhead
    stamp_ns: int
    offset_ns: int  # stamp - playhead
    chosen: bool = False  # the frame set's chosen frame (playhead at the set)
    flags: tuple[str, ...] = ()  # quality warnings of the chosen frame
    corners: tuple[tuple[float, float], ...] = ()  # detected target corners, image pixels


def set_time_ns(frame_set: FrameSet) -> int:
    """Where a set sits on the session clock: the median stamp of its chosen frames.

    That is the trigger time for nearest-frame sets and the common still time chosen by
    the best-still-frame search otherwise; a set with no frames falls back to ``t_ns``.
    """
    stamps = sorted(f.stamp_ns for f in frame_set.frames if f.index >= 0)
    return stamps[len(stamps) // 2] if stamps else frame_set.t_ns


def _saving_once(method: Callable[..., Any]) -> Callable[..., Any]:
    """``method`` with the saves it asks for held back to one as it ends, once its step
    is on the undo or redo stack: one action is one save (one ``.bak``: C saved twice),
    of the state the action ended in, its undo and redo stacks included."""

    @functools.wraps(method)
    def run(self: ReviewModel, *args: Any, **kwargs: Any) -> Any:
        self._holding += 1
        try:
            return method(self, *args, **kwargs)
        finally:
            self._holding -= 1
            if not self._holding and self._save_held:
                self._save_held = False
                self._save()

    return run


class ReviewModel:
    """Review state over a session and its recording."""

    def __init__(
        self,
        session: Session,
        source: FrameSource | None = None,
        autosave: Callable[[Session], None] | None = None,
    ) -> None:
        self.session = session
        self.source = source
        self._autosave = autosave
        self._listeners: dict[str, list[Callable[..., None]]] = {e: [] for e in EVENTS}
        # the steps of the last review, when the session file kept them for these sets
        # (read before anything moves a set); each save replaces them
        history = read_history(session.extra.get(UNDO_HISTORY_KEY), session)
        self._undo: list[UndoStep] = history.undo
        self._redo: list[UndoStep] = history.redo
        #: why the undo steps saved with the session were dropped ("" when they were read
        #: back, or there were none), for the window to say
        self.history_note = history.note
        self._history = HistoryWriter()
        # saves held back while an action runs (:func:`_saving_once`)
        self._holding = 0
        self._save_held = False
        #: per set, the frames it showed before an offset edit whose re-scoring has not
        #: landed yet (what a decision made before the edit looked at)
        self._shown_before_edit = _read_frames_before_edit(
            session.extra.get(FRAMES_BEFORE_EDIT_KEY), set(rescore_ids(session)))
        #: ids of the accepted sets the last re-scoring gave other frames than they showed
        #: (before the offset edit, or until then for an added set): an export would write
        #: frames nobody looked at
        self.accepted_with_new_frames: list[int] = []
        self._stamps = (
            {s.name: source.stamps(s.name) for s in source.streams} if source else {}
        )
        self._periods = {k: frame_period_ns(v) for k, v in self._stamps.items()}
        #: per stream, the nearest-frame choices made so far by frame index (given again
        #: by the next offset edit that picks the frame)
        self._nearest_known: dict[str, dict[int, FrameChoice]] = {k: {} for k in self._stamps}
        #: per set id, the set and its time (:func:`set_time_ns`) as last worked out
        self._times: dict[int, tuple[FrameSet, int]] = {}
        #: a clap drag's preview (see :meth:`preview_offset`): the playhead before it,
        #: whether that was at the current set, and where the preview put the playhead
        self._preview: tuple[int, bool, int] | None = None
        self._follow_sync()
        self.current = 0 if session.sets else -1
        #: which sets the list shows and J/K/Home/End step through (one of FILTERS)
        self.filter = "all"
        #: after accept or reject, go on to the next set the filter shows: an operator
        #: deciding a session's sets one by one presses A or R, not A then K (the window
        #: turns it on; off, a decision leaves the current set where it is)
        self.advance_after_decision = False
        #: what "find more like this" (S) should search for, set by :meth:`find_similar`
        #: for the window to run; with the reason when there is nothing to search
        self.similar_wanted: SimilarRequest | None = None
        self.similar_refused = ""
        #: the audio's length (seconds) once the window has read it: the playhead may go
        #: wherever there is audio too
        self.audio_duration_s = 0.0
        #: the id of the set the last accept or reject was on (it may have moved on since)
        self.last_decided: int | None = None
        #: why the last J / K / Home / End went nowhere ("" when it went to a set), or
        #: A / R / Del with no set left, for the window to say: a key that seems to do
        #: nothing leaves the operator guessing
        self.step_refused = ""
        self._resume_place(session.extra.get(REVIEW_PLACE_KEY))
        #: where the review was at the last save (a close saves only a move since)
        self._saved_place = self._place()
        self.playhead_ns = set_time_ns(session.sets[self.current]) if session.sets \
            else self._first_stamp()

    # -- events -------------------------------------------------------------------------
    def connect(self, event: str, callback: Callable[..., None]) -> None:
        """Call ``callback`` whenever ``event`` (one of :data:`EVENTS`) happens."""
        self._listeners[event].append(callback)

    def _emit(self, event: str, *args: object) -> None:
        for cb in list(self._listeners[event]):
            cb(*args)

    # -- queries ------------------------------------------------------------------------
    @property
    def streams(self) -> list[str]:
        return list(self._stamps)

    @property
    def current_set(self) -> FrameSet | None:
        return self.session.sets[self.current] if self.current >= 0 else None

    def time_range_ns(self) -> tuple[int, int]:
        """First and last stamp over all streams."""
        if not self._stamps:
            return (self.playhead_ns, self.playhead_ns)
        return (min(int(s[0]) for s in self._stamps.values() if len(s)),
                max(int(s[-1]) for s in self._stamps.values() if len(s)))

    def tiles(self) -> list[TileState]:
        """Per camera, what to show at the playhead.

        At a frame set's time these are the set's chosen frames (with their warnings);
        elsewhere the frame nearest the playhead, or none within half a frame period.
        """
        current = self.current_set
        if current is not None and self.playhead_ns == set_time_ns(current):
            chosen = {f.stream: f for f in current.frames}
            if set(chosen) >= set(self._stamps):
                return [TileState(f.stream, f.index, f.stamp_ns, f.stamp_ns - self.playhead_ns,
                                  True, f.flags, self.corners(current.id, f.stream))
                        for f in (chosen[n] for n in self._stamps)]
        out = []
        for name, stamps in self._stamps.items():
            if len(stamps) == 0:
                out.append(TileState(name, -1, 0, 0))
                continue
            near = nearest_choice(name, stamps, self.playhead_ns, self._periods[name])
            out.append(TileState(name, near.index, near.stamp_ns,
                                 near.stamp_ns - self.playhead_ns))
        return out

    def nearest_frame_offset_ns(self, stream: str) -> int | None:
        """How far the camera's frame nearest the playhead lies from it (None: no frames)."""
        stamps = self._stamps.get(stream)
        if stamps is None or len(stamps) == 0:
            return None
        i = int(np.searchsorted(stamps, self.playhead_ns))
        near = [int(stamps[j]) for j in (i - 1, i) if 0 <= j < len(stamps)]
        return min((t - self.playhead_ns for t in near), key=abs)

    def corners(self, set_id: int, stream: str) -> tuple[tuple[float, float], ...]:
        """Target corners found in a set's chosen frame of ``stream`` (empty if none)."""
        details = self.session.extra.get("frame_details")
        try:
            points = details[str(set_id)]["frames"][stream]["points"]  # type: ignore[index]
            return tuple((float(x), float(y)) for x, y in points)
        except (KeyError, TypeError, ValueError):
            return ()

    def preview_offset(self, delta_ns: int) -> None:
        """Show (without applying) where the playhead goes once the offset is shifted by
        ``delta_ns`` (see :meth:`_playhead_after`): at the current set, to the set at its
        trigger's shifted time, where it takes the nearest frames until re-scored (its
        chosen still frame may lie a few tenths of a second from the trigger); elsewhere
        it stays on the sound under it, so a playhead on the clap rides with the clap
        handle. No shift puts the playhead back where it was."""
        before, at_set = self._preview_anchor()
        current = self.current_set
        if not delta_ns:
            target = before
        elif at_set and current is not None:
            target = current.t_ns + int(delta_ns)
        else:
            target = before + int(delta_ns)
        self.set_playhead(target)
        self._preview = (before, at_set, self.playhead_ns) if delta_ns else None

    def _preview_anchor(self) -> tuple[int, bool]:
        """The playhead as it was before a clap drag's preview moved it, and whether it was
        at the current set (its chosen frames shown): the playhead now, unless the preview
        put it there (playback or a click since moved it on)."""
        preview = self._preview
        if preview is not None and preview[2] == self.playhead_ns:
            return preview[0], preview[1]
        current = self.current_set
        return self.playhead_ns, current is not None and self.playhead_ns == set_time_ns(current)

    def shown(self) -> list[int]:
        """Indices of the sets the filter shows (the current set may be among the hidden)."""
        return shown_indices(self.session.sets, self.filter)

    def set_at_playhead(self, tolerance_ns: int = 50_000_000) -> FrameSet | None:
        """The frame set whose time is within ``tolerance_ns`` of the playhead (of sets at
        the same time, such as a false trigger that took a real set's frames, the current
        one)."""
        best, best_d = None, tolerance_ns + 1
        sets = self.session.sets
        # while listeners hear of a changed list, ``current`` may not be set yet
        first = [sets[self.current]] if 0 <= self.current < len(sets) else []
        for s in first + sets:
            d = abs(self._time_of(s) - self.playhead_ns)
            if d < best_d:
                best, best_d = s, d
        return best

    def _time_of(self, frame_set: FrameSet) -> int:
        """:func:`set_time_ns` of ``frame_set``, worked out once per set (sets are
        immutable: a changed set is another object)."""
        known = self._times.get(frame_set.id)
        if known is not None and known[0] is frame_set:
            return known[1]
        t_ns = set_time_ns(frame_set)
        self._times[frame_set.id] = (frame_set, t_ns)
        return t_ns

    def acting_set(self) -> FrameSet | None:
        """The set the keys A, R, Del and S act on: the current set, unless the playhead
        was moved off it onto another set (clicked there, or playback stopped there): then
        that one, the set the grid and the line under it show."""
        current = self.current_set
        if current is not None and self.playhead_ns != set_time_ns(current):
            return self.set_at_playhead() or current
        return current

    # -- navigation actions -------------------------------------------------------------
    def set_playhead(self, t_ns: int) -> None:
        """Move the playhead to ``t_ns``, within the frames and the audio (the real clap
        may lie before the first frame, see :meth:`clap_at_playhead`)."""
        self.playhead_ns = self._within_reach(t_ns)
        self._emit("playhead", self.playhead_ns)

    def _within_reach(self, t_ns: int) -> int:
        """``t_ns`` kept within the frames and the audio (on the session's sync)."""
        lo, hi = self.time_range_ns()
        if self.audio_duration_s:
            sync = self.session.sync
            lo = min(lo, int(sync.to_session(0.0)))
            hi = max(hi, int(sync.to_session(self.audio_duration_s)))
        return int(min(max(t_ns, lo), hi)) if hi > lo else int(t_ns)

    def go_to_set(self, index: int) -> None:
        if not self.session.sets:
            return
        self.current = int(min(max(index, 0), len(self.session.sets) - 1))
        self._emit("current_set", self.current)
        self.set_playhead(set_time_ns(self.session.sets[self.current]))

    def click_word(self, set_id: int, t_ns: int) -> None:
        """A click at ``t_ns`` on the word of the set with id ``set_id`` (its mark on the
        waveform): that set becomes current, its frames shown (a set's time is its
        stillest frame, often after the word); on the current set's own word the playhead
        moves to ``t_ns`` instead, to listen from inside the word."""
        current = self.current_set
        if current is not None and current.id == set_id:
            self.set_playhead(t_ns)
        elif any(s.id == set_id for s in self.session.sets):
            self.go_to_set(self._index_of(set_id))

    def next_set(self) -> None:
        """The next set the filter shows (the current one again at the end)."""
        self._step_set(+1)

    def previous_set(self) -> None:
        self._step_set(-1)

    def first_set(self) -> None:
        shown = self.shown()
        self.step_refused = "" if shown else self._none_listed()
        if shown:
            self.go_to_set(shown[0])

    def last_set(self) -> None:
        shown = self.shown()
        self.step_refused = "" if shown else self._none_listed()
        if shown:
            self.go_to_set(shown[-1])

    def _none_listed(self) -> str:
        """Why there is no set to go to: none at all, or none the filter lists."""
        if not self.session.sets:
            return "no frame sets to go to: T adds one at the playhead"
        return (f"no {self.filter} sets listed: F steps through the filters (“all” lists "
                "every set)")

    def _step_set(self, direction: int) -> None:
        """To the next (``direction`` +1) or previous shown set: from the playhead when it
        was moved off the current set (clicked between sets: the sets around it, the
        current one aside, so that a frame stepped back from it and K still go on; past
        the last one, the last), else from the current set."""
        shown = self.shown()
        current = self.current_set
        self.step_refused = "" if shown else self._none_listed()
        if shown and current is not None and self.playhead_ns != set_time_ns(current):
            times = {i: self._time_of(self.session.sets[i]) for i in shown}
            around = [i for i in shown if (times[i] - self.playhead_ns) * direction > 0
                      and i != self.current]
            self.go_to_set(min(around or shown, key=lambda i: abs(times[i] - self.playhead_ns)))
            return
        ahead = [i for i in shown if (i - self.current) * direction > 0]
        if ahead:
            self.go_to_set(ahead[0] if direction > 0 else ahead[-1])
            return
        if current is not None and shown:
            kind = "" if self.filter == "all" else f"{self.filter} "
            side = "after" if direction > 0 else "before"
            self.step_refused = f"no {kind}set listed {side} set #{current.id}"
        if self.current in shown:
            self.go_to_set(self.current)  # at the end: back to the set, playhead included

    # -- the list's filter --------------------------------------------------------------
    def set_filter(self, name: str) -> None:
        """Show only the sets with one decision (or ``all``); the current set stays."""
        if name not in FILTERS:
            raise ValueError(f"filter must be one of {FILTERS}, got {name!r}")
        if name != self.filter:
            self.filter = name
            self._emit("filter", name)

    def next_filter(self) -> None:
        """The next of :data:`FILTERS` (after the last, ``all`` again)."""
        self.set_filter(FILTERS[(FILTERS.index(self.filter) + 1) % len(FILTERS)])

    def next_frame(self) -> None:
        self._step_frame(+1)

    def previous_frame(self) -> None:
        self._step_frame(-1)

    def next_frame_of_every_camera(self) -> None:
        self._step_frame(+1, every_camera=True)

    def previous_frame_of_every_camera(self) -> None:
        self._step_frame(-1, every_camera=True)

    def _step_frame(self, direction: int, every_camera: bool = False) -> None:
        """Move the playhead to the next/previous stamp of any camera, or with
        ``every_camera`` as far as every camera's next/previous stamp (each camera then
        shows another frame: with a dozen free-running cameras the next stamp of any
        lies a few milliseconds on)."""
        candidates = []
        for stamps in self._stamps.values():
            i = np.searchsorted(stamps, self.playhead_ns, side="right" if direction > 0 else "left")
            j = i if direction > 0 else i - 1
            if 0 <= j < len(stamps):
                candidates.append(int(stamps[j]))
        if candidates:
            forward = max if every_camera else min
            backward = min if every_camera else max
            self.set_playhead(forward(candidates) if direction > 0 else backward(candidates))

    # -- sync edits ---------------------------------------------------------------------
    def nudge_offset(self, delta_ns: int) -> None:
        """Shift the audio-to-session offset (manual clap correction) and re-pick frames.
        No shift (the clap handle released where it was) changes nothing."""
        if int(delta_ns) == 0:
            self.preview_offset(0)  # the playhead back from a drag's preview
            return
        self.set_sync(self.session.sync.with_offset(self.session.sync.offset_ns + int(delta_ns)))

    def camera_clap_ns(self) -> int | None:
        """Where the cameras saw the first clap (session clock); None for a session
        without one (its offset given by hand)."""
        claps = self.session.sync_evidence.get("claps")
        first = claps[0] if isinstance(claps, list) and claps else None
        value = first.get("session_ns") if isinstance(first, dict) else None
        return int(value) if isinstance(value, (int, float)) else None

    @_saving_once
    def clap_at_playhead(self) -> None:
        """Key C: the sound under the playhead is the clap. The offset moves so that it
        lands where the cameras saw the clap: the fix when another sound (a knock, a
        door) was taken for it. Nothing without a camera clap (see :meth:`camera_clap_ns`),
        nor with the clap at the playhead already (no shift, no step to undo)."""
        seen = self.camera_clap_ns()
        if seen is None or seen == self.playhead_ns:
            return
        heard_s = self.session.sync.to_audio(self.playhead_ns)
        # the playhead stays on that sound, now at the cameras' clap: the grid shows the
        # clap's frames, and a refining C or [ ] starts from there (undo restores the
        # clap heard too)
        sync = self.session.sync
        self.set_sync(sync.with_offset(sync.offset_ns + seen - self.playhead_ns),
                      playhead_ns=seen)
        # replaced, never changed in place: a save may be encoding the old ones
        evidence = self.session.sync_evidence
        claps = list(evidence["claps"])
        claps[0] = {**claps[0], "audio_s": float(heard_s), "audio_source": "manual"}
        self.session.sync_evidence = {**evidence, "claps": claps}
        self._emit("sync", self.session.sync)  # the clap handle goes to that sound
        self._save()

    def nudge_offset_frame(self, direction: int) -> None:
        """Shift the offset by one frame period of the fastest camera."""
        periods = [p for p in self._periods.values() if p > 0]
        self.nudge_offset(direction * (min(periods) if periods else 33_333_333))

    def set_sync(self, sync: SyncModel, playhead_ns: int | None = None) -> None:
        """Use another sync model: every set's time follows it (one undo step).

        Sets that move take the frames nearest their new time, without figures, until
        re-scored (see :meth:`rescore_request`). The playhead goes to ``playhead_ns``, by
        default where :meth:`_playhead_after` says.
        """
        anchor = self._preview_anchor()
        self._undo.append(self._sync_state())
        self._redo.clear()
        self._keep_shown_before_edit()
        self._change_sync(sync, anchor, playhead_ns)

    def _keep_shown_before_edit(self) -> None:
        """Note the frames each set shows before the sync changes and its sets wait for
        re-scoring (a set waiting already keeps what it showed before)."""
        for frame_set in self.session.sets:
            if frame_set.id not in self._shown_before_edit and not self.needs_rescore(frame_set):
                self._shown_before_edit[frame_set.id] = _frame_keys(frame_set)

    def _sync_state(self) -> OffsetChanged:
        """An undo step restoring the sync as it is now, with the sets' frames, their
        details and what their figures were judged against (MEASURED_FOR_SYNC), all
        measured for it (undoing an edit needs no re-scoring)."""
        measured = {key: dict(value) for key in MEASURED_FOR_SYNC
                    if isinstance(value := self.session.extra.get(key), dict)}
        return OffsetChanged(self.session.sync, tuple(self.session.sets), measured,
                             copy.deepcopy(self.session.sync_evidence))

    def _change_sync(self, sync: SyncModel, anchor: tuple[int, bool],
                     playhead_ns: int | None = None) -> None:
        """Take ``sync``; the playhead goes to ``playhead_ns``, by default where
        :meth:`_playhead_after` says from ``anchor``."""
        old = self.session.sync
        self.session.sync = sync
        self._follow_sync()
        self._preview = None
        self.playhead_ns = self._playhead_after(old, anchor) if playhead_ns is None \
            else self._within_reach(playhead_ns)
        self._emit("sync", sync)
        self._emit("playhead", self.playhead_ns)
        self._save()

    def _playhead_after(self, old: SyncModel, anchor: tuple[int, bool]) -> int:
        """Where the playhead goes once the sync changed from ``old``, from ``anchor`` (the
        playhead before, and whether it was at the current set): with the current set, at
        its new time, its frames shown as the edit picks them; elsewhere on the same sound,
        which the edit moved: a playhead put on the clap to refine the offset stays on it
        (it jumped back to the set), and one following playback stays with the sound."""
        before, at_set = anchor
        current = self.current_set
        if at_set and current is not None:
            return set_time_ns(current)
        return self._within_reach(int(self.session.sync.to_session(old.to_audio(before))))

    # -- decisions ----------------------------------------------------------------------
    def accept(self) -> None:
        self.decide("accepted")

    def reject(self) -> None:
        self.decide("rejected")

    def decide(self, decision: str) -> None:
        """Record a decision on the current set (then autosave).

        With the playhead moved off the current set, the set at the playhead is decided
        when there is one, else the current set; the playhead returns to the decided set,
        so the grid shows the frames the decision is on. With
        :attr:`advance_after_decision`, the next set the filter shows after it becomes
        current (also when the set had that decision already); after the last one the
        decided set stays current.
        """
        current = self.acting_set()
        self.step_refused = ""  # an earlier key's reason; "then next set" may give its own
        if current is None:  # none left: the key says why it did nothing
            self.step_refused = NO_SETS_LEFT.format(verb="decide on")
            return
        if self.playhead_ns != set_time_ns(current) or current is not self.current_set:
            self.go_to_set(self._index_of(current.id))
        self.last_decided = current.id
        if current.decision != decision:
            self._undo.append(Decided(current.id, current.decision))
            self._redo.clear()
            self._apply(current.id, decision)
        if self.advance_after_decision:
            self.next_set()

    @_saving_once
    def undo(self) -> None:
        if self._undo:
            self._redo.append(self._revert(self._undo.pop()))

    @_saving_once
    def redo(self) -> None:
        if self._redo:
            self._undo.append(self._revert(self._redo.pop()))

    @property
    def removed_here(self) -> bool:
        """Whether a set removed in this review could still be put back (undo)."""
        return any(isinstance(step, Removed) for step in self._undo)

    @property
    def undo_label(self) -> str:
        """What :meth:`undo` would take back, in words ("" when nothing), for a menu."""
        return step_label(self._undo[-1]) if self._undo else ""

    @property
    def redo_label(self) -> str:
        """What :meth:`redo` would do again, in words ("" when nothing)."""
        return step_label(self._redo[-1], redo=True) if self._redo else ""

    def _revert(self, step: UndoStep) -> UndoStep:
        """Take one step back; returns the step that takes this back in turn."""
        if isinstance(step, OffsetChanged):
            anchor = self._preview_anchor()  # before the sets change their frames
            now = self._sync_state()
            self.session.sync_evidence = copy.deepcopy(step.evidence)  # a clap C moved
            # the stack holds no later step, so the same sets are in: only their frames
            # (and figures) differ, measured for the other sync
            by_id = {s.id: s for s in step.sets}
            self.session.sets[:] = [replace(s, frames=by_id[s.id].frames, t_ns=by_id[s.id].t_ns)
                                    if s.id in by_id else s for s in self.session.sets]
            for key in MEASURED_FOR_SYNC:  # a session may have had none of them
                if key in step.measured:
                    self.session.extra[key] = dict(step.measured[key])
                else:
                    self.session.extra.pop(key, None)
            waiting = set(self.rescore_ids())  # the others show scored frames again
            self._shown_before_edit = {i: keys for i, keys in self._shown_before_edit.items()
                                       if i in waiting}
            self._change_sync(step.sync, anchor)
            return now
        if isinstance(step, EarlierOffsetChange):
            anchor = self._preview_anchor()
            now = self._sync_state()
            evidence = {k: v for k, v in self.session.sync_evidence.items() if k != "claps"}
            if step.claps is not None:
                evidence["claps"] = copy.deepcopy(list(step.claps))
            self.session.sync_evidence = evidence
            self._keep_shown_before_edit()  # its frames and figures were not kept
            self._change_sync(step.sync, anchor)
            return now
        if isinstance(step, Decided):
            now_decided = self.session.set_by_id(step.set_id).decision
            self._apply(step.set_id, step.previous, select=True)
            return Decided(step.set_id, now_decided)
        if isinstance(step, Added):
            index = self._index_of(step.set_id)
            frame_set = self.session.sets[index]  # as it is now (re-scored, decided)
            return Removed(frame_set, index, self._drop_set(index))
        if isinstance(step, Removed):
            self._insert_set(step.frame_set, step.index, step.details)
            return Added(step.frame_set.id)
        # a search's sets; the step may carry detection settings: to put back now, and
        # the ones now, put back when this is taken back in turn
        swapped = None
        if step.settings is not None:
            restore_settings(self.session, step.settings[0])
            swapped = (step.settings[1], step.settings[0])
        if isinstance(step, AddedMany):
            return RemovedMany(tuple(self._drop_sets(list(step.set_ids))), swapped)
        return AddedMany(tuple(self._insert_sets(list(step.items))), swapped)

    def _apply(self, set_id: int, decision: str, select: bool = False) -> None:
        self.session.replace_set(self.session.set_by_id(set_id).with_decision(decision))
        if select:
            index = next(i for i, s in enumerate(self.session.sets) if s.id == set_id)
            if index != self.current:
                self.go_to_set(index)
        self._emit("decision", set_id, decision)
        self._save()

    # -- adding and removing sets ---------------------------------------------------------
    def add_set(self) -> None:
        """Add a frame set at the playhead, for a trigger word the detector missed.

        Its trigger is operator-added (``source`` :data:`OPERATOR_SOURCE`), with the
        session's first trigger word and a zero-length word span: ``start_s == end_s`` is
        the playhead mapped to audio time. Every camera shows the frame nearest the
        playhead until it is re-scored like a detected trigger's (:meth:`rescore_request`).
        Within :data:`ADD_MIN_GAP_NS` of an existing set, its frames or its word (often
        half a second before the frames), nothing is added; that set is selected instead.
        The new set is undecided and becomes the current set.
        """
        near = self._set_near_playhead(ADD_MIN_GAP_NS)
        if near is not None:
            self.go_to_set(self._index_of(near.id))
            return
        t_s = float(self.session.sync.to_audio(self.playhead_ns))
        word = self.session.triggers_word[0] if self.session.triggers_word else "capture"
        new = self._new_set(Trigger(word, t_s, t_s, 1.0, OPERATOR_SOURCE), self.playhead_ns)
        index = sum(1 for s in self.session.sets if s.t_ns <= new.t_ns)
        self._frame_details()  # from now on, sets without details are re-scored
        self._undo.append(Added(new.id))
        self._redo.clear()
        self._insert_set(new, index, None)

    def _set_near_playhead(self, gap_ns: int) -> FrameSet | None:
        """The set closest to the playhead, by its frames' time or its word's span on the
        session clock, if within ``gap_ns``."""
        best, best_d = None, gap_ns + 1
        for s in self.session.sets:
            start = int(self.session.sync.to_session(s.trigger.start_s))
            end = int(self.session.sync.to_session(s.trigger.end_s))
            to_word = max(start - self.playhead_ns, 0, self.playhead_ns - end)
            d = min(to_word, abs(set_time_ns(s) - self.playhead_ns))
            if d < best_d:
                best, best_d = s, d
        return best

    def _new_set(self, trigger: Trigger, at_ns: int | None = None,
                 set_id: int | None = None) -> FrameSet:
        """An undecided set for ``trigger`` with every camera's frame nearest ``at_ns``
        (default: the trigger's time), to be re-scored like a detected trigger's."""
        t_ns = int(self.session.sync.to_session(trigger.t_s))
        at = t_ns if at_ns is None else at_ns
        frames = tuple(nearest_choice(name, st, at, self._periods[name])
                       for name, st in self._stamps.items())
        if set_id is None:
            set_id = self.session.new_set_id()  # never a removed set's number
        return FrameSet(id=set_id, t_ns=t_ns, trigger=trigger, frames=frames)

    # -- find more like this ------------------------------------------------------------
    def find_similar(self) -> None:
        """Ask for a search of the audio for more words like the current set's (key S).

        The search runs elsewhere (it reads the audio file): this only says what to
        search for in :attr:`similar_wanted` (or why not in :attr:`similar_refused`) and
        tells ``"similar"`` listeners; :meth:`apply_similar` takes the words found.
        """
        current = self.acting_set()
        self.similar_wanted, self.similar_refused = None, ""
        if current is None:
            self.similar_refused = ("no frame set to search from: put the playhead on a "
                                    "trigger word, add a set there (T), then press S")
        elif not self.session.audio:
            self.similar_refused = "this session has no audio file to search"
        else:
            self.similar_wanted = self.similar_request(current.id)
        self._emit("similar", self.similar_wanted)

    def similar_request(self, set_id: int | None = None) -> SimilarRequest | None:
        """What to search for to find more like set ``set_id`` (default: the current set)."""
        frame_set = (self.current_set if set_id is None
                     else next((s for s in self.session.sets if s.id == set_id), None))
        return similar_request(self.session, frame_set) if frame_set is not None else None

    @_saving_once
    def apply_similar(self, result: SimilarResult) -> list[int]:
        """Add a set for every word found that no set covers; returns their ids.

        Each new set is undecided, its trigger's ``source`` :data:`SIMILAR_SOURCE`, with
        the frames nearest its time until re-scored (as :meth:`add_set` does). A word
        within :data:`ADD_MIN_GAP_NS` of a set (one added or found meanwhile too) is
        skipped. All of them are one undo step; the current set stays current.
        """
        return self._add_found([Trigger(w.word, w.start_s, w.end_s, w.score, SIMILAR_SOURCE)
                                for w in result.words])

    @_saving_once
    def apply_detected(self, result: DetectResult) -> list[int]:
        """Add a set for every trigger word detected again that no set covers (as
        :meth:`apply_similar` does, the detector's ``source`` kept); returns their ids.

        When it found any, the request's words and sensitivity become the session's
        (``record_settings``): its words come first, the word of a set added with T. The
        undo step that takes the sets back puts the earlier settings back too.
        """
        before = settings_of(self.session)
        if result.words:
            record_settings(self.session, result.request)
        added = self._add_found([Trigger(w.word, w.start_s, w.end_s, w.score,
                                         w.source or "detector") for w in result.words])
        if added:  # undo restores the settings, redo records them again
            step = self._undo[-1]
            assert isinstance(step, AddedMany)
            self._undo[-1] = replace(step, settings=(before, settings_of(self.session)))
        elif result.words:
            self._save()  # the settings changed, no set did
        return added

    def _add_found(self, triggers: list[Trigger]) -> list[int]:
        """New undecided sets for the ``triggers`` no set covers, as one undo step."""
        times = [set_time_ns(s) for s in self.session.sets] + \
            [s.t_ns for s in self.session.sets]
        added: list[tuple[FrameSet, int, object]] = []
        for trigger in triggers:
            new = self._new_set(trigger, set_id=0)  # numbered once kept
            if any(abs(new.t_ns - t) < ADD_MIN_GAP_NS for t in times):
                continue
            times.append(new.t_ns)
            added.append((replace(new, id=self.session.new_set_id()), -1, None))
        if not added:
            return []
        self._frame_details()  # from now on, sets without details are re-scored
        ids = self._insert_sets(added)
        self._undo.append(AddedMany(tuple(ids)))
        self._redo.clear()
        return ids

    @_saving_once
    def remove_set(self) -> None:
        """Remove the set the keys act on (:meth:`acting_set`: a false trigger); undo
        brings it back."""
        current = self.acting_set()
        self.step_refused = ""  # an earlier key's reason
        if current is None:
            self.step_refused = NO_SETS_LEFT.format(verb="remove")
            return
        index = self._index_of(current.id)
        details = self._drop_set(index)
        self._undo.append(Removed(current, index, details))
        self._redo.clear()

    def _index_of(self, set_id: int) -> int:
        return next(i for i, s in enumerate(self.session.sets) if s.id == set_id)

    def _insert_set(self, frame_set: FrameSet, index: int, details: object) -> None:
        """Put a set back (or in) at ``index``, select it, tell listeners, save.

        A set taken out before an offset edit comes back at its new time, with nearest
        frames and without details (to be re-scored).
        """
        if frame_set.t_ns != int(self.session.sync.to_session(frame_set.trigger.t_s)):
            frame_set, details = self._nearest_set(frame_set), None
        if not 0 <= index <= len(self.session.sets):  # a place the list has not: by time
            index = sum(1 for s in self.session.sets if s.t_ns <= frame_set.t_ns)
        self.session.sets.insert(index, frame_set)
        all_details = self.session.extra.get("frame_details")
        if isinstance(all_details, dict):
            if details is None:
                all_details.pop(str(frame_set.id), None)  # never show another set's corners
            else:
                all_details[str(frame_set.id)] = details
        self._emit("sets")
        self.go_to_set(index)
        self._save()

    def _insert_sets(self, items: list[tuple[FrameSet, int, object]]) -> list[int]:
        """Put several sets in at once (index -1: in time order), with their details;
        the current set stays current. One event, one save; returns their ids."""
        current = self.current_set
        all_details = self._frame_details()
        for frame_set, index, details in sorted(items, key=lambda item: item[1]):
            if frame_set.t_ns != int(self.session.sync.to_session(frame_set.trigger.t_s)):
                frame_set, details = self._nearest_set(frame_set), None
            if index < 0 or index > len(self.session.sets):
                index = sum(1 for s in self.session.sets if s.t_ns <= frame_set.t_ns)
            self.session.sets.insert(index, frame_set)
            if details is None:
                all_details.pop(str(frame_set.id), None)
            else:
                all_details[str(frame_set.id)] = details
        self._emit("sets")
        self._reselect(current)
        self._save()
        return [item[0].id for item in items]

    def _drop_sets(self, set_ids: list[int]) -> list[tuple[FrameSet, int, object]]:
        """Take several sets out at once; returns (set, index, details) for undo, each
        index as it was with the others still in. One event, one save."""
        current = self.current_set
        all_details = self._frame_details()
        wanted = set(set_ids)
        out = [(s, i, all_details.pop(str(s.id), None))
               for i, s in enumerate(self.session.sets) if s.id in wanted]
        self.session.sets[:] = [s for s in self.session.sets if s.id not in wanted]
        self._emit("sets")
        self._reselect(current if current is not None and current.id not in wanted else None,
                       min((i for _s, i, _d in out), default=0))
        self._save()
        return out

    def _reselect(self, frame_set: FrameSet | None, fallback: int = 0) -> None:
        """Keep ``frame_set`` current after the list changed (else the set at
        ``fallback``, or none), and tell listeners where it now is."""
        if not self.session.sets:
            self.current = -1
            self._emit("current_set", self.current)
            self._emit("playhead", self.playhead_ns)
            return
        if frame_set is not None and any(s.id == frame_set.id for s in self.session.sets):
            self.current = self._index_of(frame_set.id)
            self._emit("current_set", self.current)
            return
        self.go_to_set(self._shown_from(fallback))

    def _shown_from(self, index: int) -> int:
        """The first set the filter shows from ``index`` on, else the last it shows before
        it (a set the list hides is no place to land after a removal); ``index`` itself,
        kept in range, when it shows none."""
        shown = self.shown()
        later = [i for i in shown if i >= index]
        if later:
            return later[0]
        return shown[-1] if shown else min(index, len(self.session.sets) - 1)

    def _drop_set(self, index: int) -> object:
        """Take the set at ``index`` out; the next one the filter shows (or the last
        shown) becomes current.

        Returns the set's frame details from the session extras (None if it had none),
        so undo can put them back.
        """
        frame_set = self.session.sets.pop(index)
        all_details = self.session.extra.get("frame_details")
        details = (all_details.pop(str(frame_set.id), None)
                   if isinstance(all_details, dict) else None)
        self._emit("sets")
        if self.session.sets:
            self.go_to_set(self._shown_from(index))
        else:
            self.current = -1
            self._emit("current_set", self.current)
            self._emit("playhead", self.playhead_ns)
        self._save()
        return details

    # -- re-scoring -----------------------------------------------------------------------
    def needs_rescore(self, frame_set: FrameSet) -> bool:
        """Whether a set shows nearest frames that the best-still search should replace
        (see :func:`speechcal_core.review.rescore.needs_rescore`)."""
        return needs_rescore(self.session, frame_set)

    def rescore_ids(self) -> list[int]:
        """Ids of the sets that need re-scoring (see :meth:`needs_rescore`), in order."""
        return rescore_ids(self.session)

    def export_waits_for(self, include_undecided: bool = False) -> list[int]:
        """Ids of the sets an export would hold that still wait for re-scoring (an export
        started now would write their nearest frames, not the best still ones)."""
        return export_waits_for(self.session, include_undecided=include_undecided)

    def rescore_request(self) -> RescoreRequest | None:
        """What to re-score now (None: nothing, or no recording to read); see
        :func:`speechcal_core.review.rescore.rescore_request`."""
        return rescore_request(self.session) if self.source is not None else None

    def apply_rescored(self, result: RescoreResult) -> list[int]:
        """Take re-scored sets; returns the ids taken (then tells listeners and saves).

        A result for another sync than the current one is stale and dropped whole; sets
        removed meanwhile are skipped. Decisions stay as they are now; accepted sets given
        other frames than they showed before the offset edit (or, for sets no offset
        edit moved, until now: added sets show their nearest frames) are listed in
        :attr:`accepted_with_new_frames`. When the playhead is at the current set it moves
        to the set's new chosen time.
        """
        current = self.current_set
        at_current = current is not None and self.playhead_ns == set_time_ns(current)
        shown = {s.id: _frame_keys(s) for s in self.session.sets}
        taken = apply_rescore(self.session, result)
        if not taken:
            return []
        self.accepted_with_new_frames = []
        by_id = {s.id: s for s in self.session.sets}
        for set_id in taken:
            # before an offset edit's re-scoring, what the set showed before the edit;
            # otherwise (a set added with T or by a search, also one left waiting by an
            # earlier run of the window) the nearest frames it showed until now
            before = self._shown_before_edit.pop(set_id, None) or shown.get(set_id)
            frame_set = by_id[set_id]
            if before is not None and frame_set.decision == "accepted" \
                    and _frame_keys(frame_set) != before:
                self.accepted_with_new_frames.append(set_id)
        self._emit("rescored", taken)
        if at_current and self.current_set is not None:
            self.set_playhead(set_time_ns(self.current_set))
        self._save()
        return taken

    # -- coverage and calibration check -------------------------------------------------
    def checks_due(self) -> bool:
        """Whether coverage and the calibration check are for other frames or decisions
        than the session has now (they follow once re-scoring has landed)."""
        return checks_due(self.session)

    def checks_request(self) -> ChecksRequest | None:
        """What to compute them from now (None: not due, or no recording to size images)."""
        if self.source is None:
            return None
        return checks_request(self.session, stream_sizes(self.source))

    def word_stillness(self) -> WordStillness:
        """How many sets have their word at a still board, per their last best-still
        search at their present time (few: another session's audio, or a wrong offset)."""
        details = self.session.extra.get("frame_details")
        return word_stillness(self.session.sets, details if isinstance(details, dict) else {})

    def checks_wanted(self, request: ChecksRequest) -> bool:
        """Whether checks computed from ``request`` would still be taken: the session's
        frames and decisions are the ones it was made over."""
        return still_wanted(self.session, request.basis)

    def apply_checks(self, result: ChecksResult) -> bool:
        """Take recomputed checks unless frames or decisions changed meanwhile (then
        False: they are due again); tells listeners and saves."""
        if not apply_checks(self.session, result):
            return False
        self._emit("checks")
        self._save()
        return True

    def _frame_details(self) -> dict:
        """The session's per-set frame details (made empty when it has none)."""
        details = self.session.extra.get("frame_details")
        if not isinstance(details, dict):
            details = self.session.extra["frame_details"] = {}
        return details

    def _follow_sync(self) -> None:
        """Sets whose time does not follow the session's sync (moved by an offset edit, or
        read from a file whose offset was edited by hand) take the frames nearest their
        time under it, without details, until re-scored."""
        sets = self.session.sets
        if not sets:
            return
        # every set at once: an offset edit moves them all, a dozen cameras' frames each
        now = self.session.sync.to_session(np.array([s.trigger.t_s for s in sets]))
        moved = [i for i, s in enumerate(sets) if s.t_ns != int(now[i])]
        if not moved:
            return
        details = self._frame_details()
        times = [int(now[i]) for i in moved]
        for known in self._nearest_known.values():
            if len(known) > NEAREST_KNOWN_PER_SET * len(sets):  # many edits went far
                known.clear()
        nearest = [nearest_choices(name, st, times, self._periods[name],
                                   self._nearest_known[name])
                   for name, st in self._stamps.items()]
        for k, i in enumerate(moved):
            details.pop(str(sets[i].id), None)  # its corners are other frames'
            frames = tuple(choices[k] for choices in nearest)
            sets[i] = replace(sets[i], t_ns=times[k], frames=frames or sets[i].frames)

    def _nearest_set(self, frame_set: FrameSet) -> FrameSet:
        """``frame_set`` at its trigger's time under the current sync, with nearest frames."""
        t_ns = int(self.session.sync.to_session(frame_set.trigger.t_s))
        frames = tuple(nearest_choice(name, st, t_ns, self._periods[name])
                       for name, st in self._stamps.items())
        return replace(frame_set, t_ns=t_ns, frames=frames or frame_set.frames)

    def _resume_place(self, place: object) -> None:
        """Start at the set and filter of ``place`` (as saved under REVIEW_PLACE_KEY);
        a set no longer in the session, or a place not understood, leaves the start."""
        if not isinstance(place, dict):
            return
        if place.get("filter") in FILTERS:
            self.filter = str(place["filter"])
        index = next((k for k, s in enumerate(self.session.sets) if s.id == place.get("set")),
                     None)
        if index is not None:
            self.current = index

    def _place(self) -> dict[str, Any] | None:
        """Where the review is now: the current set's id and the filter."""
        current = self.current_set
        return None if current is None else {"set": current.id, "filter": self.filter}

    def save_place(self) -> None:
        """Save if the current set or the filter changed since the last save (a window
        closing: moving about saves nothing, so the file keeps its ``.bak`` of the last
        change)."""
        if self._place() != self._saved_place:
            self._save()

    def _save(self) -> None:
        if self._holding:  # once the action ends (:func:`_saving_once`)
            self._save_held = True
            return
        self._saved_place = self._place()
        if self._saved_place is not None:
            self.session.extra[REVIEW_PLACE_KEY] = self._saved_place
        if self._shown_before_edit:  # a closing before re-scoring lands keeps them
            self.session.extra[FRAMES_BEFORE_EDIT_KEY] = {
                str(i): [list(k) for k in keys] for i, keys in self._shown_before_edit.items()}
        else:
            self.session.extra.pop(FRAMES_BEFORE_EDIT_KEY, None)
        history = self._history.entry(self._undo, self._redo, self.session)
        if history is None:
            self.session.extra.pop(UNDO_HISTORY_KEY, None)
        else:
            self.session.extra[UNDO_HISTORY_KEY] = history
        if self._autosave is not None:
            self._autosave(self.session)
            self._emit("saved")

    def _first_stamp(self) -> int:
        starts = [int(s[0]) for s in self._stamps.values() if len(s)]
        return min(starts) if starts else 0

    def offset_minus_ms(self) -> None:
        self.nudge_offset(-1_000_000)

    def offset_plus_ms(self) -> None:
        self.nudge_offset(1_000_000)

    def offset_minus_frame(self) -> None:
        self.nudge_offset_frame(-1)

    def offset_plus_frame(self) -> None:
        self.nudge_offset_frame(+1)

    def trigger(self, action: str) -> None:
        """Run a named action (what a key binding maps to)."""
        getattr(self, action)()


def _read_frames_before_edit(stored: object, waiting: set[int]
                             ) -> dict[int, tuple[tuple[str, int], ...]]:
    """The frames sets showed before an offset edit, as saved under
    FRAMES_BEFORE_EDIT_KEY, for the sets still ``waiting`` for re-scoring (an export may
    have re-scored the others since); anything not understood is left out."""
    out: dict[int, tuple[tuple[str, int], ...]] = {}
    if not isinstance(stored, dict):
        return out
    for key, pairs in stored.items():
        try:
            set_id = int(key)
            keys = tuple((str(stream), int(index)) for stream, index in pairs)
        except (TypeError, ValueError):
            continue
        if set_id in waiting:
            out[set_id] = keys
    return out


def _frame_keys(frame_set: FrameSet) -> tuple[tuple[str, int], ...]:
    """Which frame of each stream a set shows."""
    return tuple((f.stream, f.index) for f in frame_set.frames)
