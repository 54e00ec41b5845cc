"""The session: recording + audio + sync + frame sets + decisions, as kept in SESSION.json."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from speechcal_core.sources.selection import StreamChoice
from speechcal_core.sync.model import SyncModel

DECISIONS = ("accepted", "rejected", "undecided")


@dataclass(frozen=True)
class Trigger:
    """A detected or operator-added trigger word, in audio seconds."""

    word: str
    start_s: float
    end_s: float
    score: float = 1.0
    source: str = "detected"  # detected | transcript | manual | truth

    @property
    def t_s(self) -> float:
        """The trigger's audio time: the mean of the word's start and end."""
        return (self.start_s + self.end_s) / 2

    def to_dict(self) -> dict[str, Any]:
        return {"word": self.word, "start_s": self.start_s, "end_s": self.end_s,
                "score": self.score, "source": self.source}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Trigger:
        return cls(str(data["word"]), _audio_s(data, "start_s"), _audio_s(data, "end_s"),
                   float(data.get("score", 1.0)), str(data.get("source", "detected")))


#: audio seconds beyond this (31 years) are a hand edit gone wrong: the session times
#: computed from them overflowed, and the review window raised
MAX_AUDIO_S = 1e9


def _audio_s(data: dict[str, Any], key: str) -> float:
    """The trigger's time ``key`` in audio seconds; ValueError naming it when it is none."""
    value = float(data[key])
    if not abs(value) < MAX_AUDIO_S:  # nan too
        raise ValueError(f"its trigger's {key} {data[key]!r:.40} is no time in the audio "
                         "(seconds)")
    return value


#: session times are int64 nanoseconds (DESIGN.md §1): beyond, a hand edit gone wrong
#: (1.5e300 read as a whole number named a file of 300 digits in an export)
INT64 = range(-(2**63), 2**63)


def _ns(value: object, what: str) -> int:
    """``value`` as int64 nanoseconds; ValueError naming ``what`` when it is none."""
    ns = int(value)  # type: ignore[call-overload]
    if isinstance(value, bool) or ns not in INT64:
        raise ValueError(f"{what} {value!r} is no camera-clock time in nanoseconds")
    return ns


#: a frame's index in its stream; more is a hand edit gone wrong (the window's frame
#: loader passes indexes as 32-bit numbers, and 10**12 raised in its thread)
MAX_FRAME_INDEX = 2**31 - 1


@dataclass(frozen=True)
class FrameChoice:
    """The frame chosen for one camera in one frame set (index -1: none within tolerance)."""

    stream: str
    index: int
    stamp_ns: int
    sharpness: float | None = None
    corners: int | None = None
    flags: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"stream": self.stream, "index": self.index, "stamp_ns": self.stamp_ns,
                "sharpness": self.sharpness, "corners": self.corners, "flags": list(self.flags)}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> FrameChoice:
        stream = str(data["stream"])
        flags = data.get("flags", ())
        if not isinstance(flags, (list, tuple)) or not all(isinstance(f, str) for f in flags):
            raise ValueError(f"{stream}'s flags is {flags!r}, not a list of flags")
        index = int(data.get("index", -1))
        if not -1 <= index <= MAX_FRAME_INDEX:
            raise ValueError(f"{stream}'s frame index is {index}, beyond any recording")
        return cls(stream, index, _ns(data["stamp_ns"], f"{stream}'s stamp_ns"),
                   _figure(data, "sharpness", float), _figure(data, "corners", int),
                   tuple(flags))


def _figure(data: dict[str, Any], key: str, kind: type) -> Any:
    """A frame's quality figure ``key`` as ``kind`` (None where it has none); ValueError
    naming it when it is no number (a hand edit: the review compares it with others)."""
    value = data.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{data['stream']}'s {key} is {value!r}, not a number")
    return kind(value)


@dataclass(frozen=True)
class FrameSet:
    """One trigger's synchronized frames and the operator's decision on them."""

    id: int
    t_ns: int
    trigger: Trigger
    frames: tuple[FrameChoice, ...]
    decision: str = "undecided"

    @property
    def skew_ns(self) -> int:
        """Largest stamp difference between the set's frames (0 with fewer than two)."""
        stamps = [f.stamp_ns for f in self.frames if f.index >= 0]
        return max(stamps) - min(stamps) if len(stamps) > 1 else 0

    @property
    def has_frames(self) -> bool:
        """Whether any camera has a frame for this set (none past the recording's end)."""
        return any(f.index >= 0 for f in self.frames)

    def with_decision(self, decision: str) -> FrameSet:
        if decision not in DECISIONS:
            raise ValueError(f"decision must be one of {DECISIONS}, got {decision!r}")
        return replace(self, decision=decision)

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "t_ns": self.t_ns, "decision": self.decision,
                "trigger": self.trigger.to_dict(), "skew_ns": self.skew_ns,
                "frames": [f.to_dict() for f in self.frames]}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> FrameSet:
        decision = str(data.get("decision", "undecided")).strip().lower()
        if decision not in DECISIONS:  # a hand edit: say so rather than lose the decision
            raise ValueError(f"decision {data.get('decision')!r} is none of "
                             f"{', '.join(DECISIONS)}")
        return cls(int(data["id"]), _ns(data["t_ns"], "its time t_ns"),
                   Trigger.from_dict(data["trigger"]),
                   tuple(FrameChoice.from_dict(f) for f in data.get("frames", ())), decision)


#: keys of ``Session.extra`` (top-level in the file) holding the detection settings last
#: used, beside ``"trigger_words"``: what the review's "find trigger words" starts from
SENSITIVITY_KEY = "trigger_sensitivity"
PRONUNCIATIONS_KEY = "trigger_pronunciations"
#: key of ``Session.extra`` (top-level in the file): the names of the recording's streams
#: the session uses, when it was made from some of them (``--stream``, ``--skip-stream``);
#: absent: all of them
STREAMS_KEY = "streams"
#: key of ``Session.extra`` (top-level in the file): where the review was when the session
#: was last saved, ``{"set": <current set id>, "filter": <the list's filter>}``, so that
#: the window opens it there again
REVIEW_PLACE_KEY = "review_place"
#: key of ``Session.extra`` (top-level in the file): per set id waiting for re-scoring
#: after an offset edit, the ``[stream, frame index]`` pairs it showed before the edit
#: (what a decision made then looked at), for a review that goes on after a reopening
FRAMES_BEFORE_EDIT_KEY = "frames_before_offset_edit"


@dataclass
class Session:
    """Everything a review needs; paths are as given (absolute after loading)."""

    recording: list[str]
    audio: str | None
    sync: SyncModel
    sets: list[FrameSet] = field(default_factory=list)
    #: the audio file's channel the session uses (0-based); None: all channels mixed
    audio_channel: int | None = None
    triggers_word: list[str] = field(default_factory=lambda: ["capture"])
    calibration: dict[str, Any] = field(default_factory=dict)
    #: what the sync was found from, as ``speechcal sync`` reports it (claps, cameras)
    sync_evidence: dict[str, Any] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)
    #: the highest set number the session has given, removed sets' too (file key
    #: ``last_set_id``): set numbers are what the operator reads and says ("set 7"), so a
    #: new set is numbered after it (:meth:`new_set_id`), never as a set removed before
    last_set_id: int = 0

    def highest_set_id(self) -> int:
        """The highest set number given so far: of the sets the session has or has had
        (a set added with an id of its own counts too)."""
        return max(self.last_set_id, max((s.id for s in self.sets), default=0))

    def new_set_id(self) -> int:
        """The number of a new set, taken: after every set the session has or has had
        (a removed set's, an undone added set's), also across saving and opening again."""
        self.last_set_id = self.highest_set_id() + 1
        return self.last_set_id

    def claps_audio_s(self) -> tuple[float, ...]:
        """The claps heard in the audio (audio seconds, from ``sync_evidence``): the first
        sets the offset, a second (at the end of the recording) the drift."""
        claps = self.sync_evidence.get("claps") or []
        return tuple(float(c["audio_s"]) for c in claps
                     if isinstance(c, dict) and isinstance(c.get("audio_s"), (int, float)))

    def stream_choice(self) -> StreamChoice | None:
        """The recording's streams the session uses (None: all of them)."""
        names = self.extra.get(STREAMS_KEY)
        return StreamChoice(only=tuple(names)) if names else None

    def set_by_id(self, set_id: int) -> FrameSet:
        for s in self.sets:
            if s.id == set_id:
                return s
        raise KeyError(set_id)

    def replace_set(self, new: FrameSet) -> None:
        """Put ``new`` in place of the set with the same id."""
        for i, s in enumerate(self.sets):
            if s.id == new.id:
                self.sets[i] = new
                return
        raise KeyError(new.id)

    def counts(self) -> dict[str, int]:
        """How many sets have each decision."""
        out = dict.fromkeys(DECISIONS, 0)
        for s in self.sets:
            out[s.decision] += 1
        return out
