"""Offset and drift from claps seen in both clocks, with per-camera residuals."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from speechcal_core.sync.model import SyncModel

MAX_DRIFT = 1e-3  # 1000 ppm: anything larger means the two claps were mismatched
#: a V fit's timing is taken as no better than this: the audio clap's onset is good to
#: about a tenth of a millisecond, and the fit's error leaves out its own biases
MIN_TIMING_SD_NS = 300_000
#: two cameras' times between the claps further apart than this (and than their timing
#: errors allow) are noted: one of them timed a clap wrongly
DISAGREE_NS = 2_000_000
#: a drift whose standard error moves the audio farthest from the first clap more than
#: this is noted (as a typical drift does over ONE_CLAP_NOTE_S without a second clap)
DOUBTFUL_SHIFT_S = 0.006


@dataclass(frozen=True)
class CameraClap:
    """One camera's view of one clap, in its own header-stamp clock."""

    name: str
    clap_ns: int
    period_ns: int = 0
    method: str = "auto"  # "v-fit", "peak" or "manual"
    frame_index: int = -1
    score: float = 0.0  # how clearly the camera saw it (clap_video's score); 0: unknown
    sigma_ns: int = 0  # the V fit's standard error of clap_ns (clap_video); 0: unknown


@dataclass(frozen=True)
class Clap:
    """One clap in both clocks: audio onset and the cameras' stamps of the hands meeting."""

    audio_s: float
    cameras: tuple[CameraClap, ...]
    audio_source: str = "auto"  # "auto" or "manual"
    video_source: str = "auto"
    session_override_ns: int | None = None  # a clap set by hand on the session clock

    @property
    def session_ns(self) -> int:
        """The clap on the session clock: the cameras' median (three or more), their mean
        weighted by inverse frame period squared (a faster camera times the clap better:
        a 30 fps camera counts four times a 15 fps one), or the manual value.

        Two cameras more than a frame apart cannot both have timed it well: the one that
        saw it more clearly is taken alone (a mean would be off by half the gap)."""
        if self.session_override_ns is not None:
            return int(self.session_override_ns)
        stamps = np.array([c.clap_ns for c in self.cameras], dtype=np.int64)
        if stamps.size == 0:
            raise ValueError("a clap needs at least one camera or a manual session time")
        base = int(stamps.min())
        rel = (stamps - base).astype(np.float64)
        if rel.size >= 3:
            return base + round(float(np.median(rel)))
        clearer = self._clearer_of_two()
        if clearer is not None:
            return int(clearer.clap_ns)
        w = np.array([timing_weight(c.period_ns) for c in self.cameras])
        return base + round(float(np.sum(w * rel) / np.sum(w)))

    def _clearer_of_two(self) -> CameraClap | None:
        """Of two cameras more than a frame period apart, the one set by hand, else the
        clearer one (None: they agree, or neither stands out)."""
        if len(self.cameras) != 2:
            return None
        a, b = self.cameras
        frame = max(a.period_ns or 33_333_333, b.period_ns or 33_333_333)

        def rank(c: CameraClap) -> tuple[bool, float]:
            return c.method == "manual", c.score

        if abs(a.clap_ns - b.clap_ns) <= frame or rank(a) == rank(b):
            return None
        return max((a, b), key=rank)

    @property
    def edited(self) -> bool:
        """Whether any part of this clap was set by hand."""
        return "manual" in (self.audio_source, self.video_source)


@dataclass(frozen=True)
class SyncResult:
    """The sync model with the claps it came from and what they say about each camera."""

    model: SyncModel
    claps: tuple[Clap, ...]
    warnings: tuple[str, ...] = ()
    extra: dict = field(default_factory=dict)

    def residuals(self) -> list[dict]:
        """Per camera: its clap stamp (first clap) and how far it sits from the model."""
        out = []
        names = [c.name for clap in self.claps for c in clap.cameras]
        for name in dict.fromkeys(names):
            res, stamp, period = [], None, 0
            for clap in self.claps:
                for cam in clap.cameras:
                    if cam.name != name:
                        continue
                    r = cam.clap_ns - int(self.model.to_session(clap.audio_s))
                    res.append(r)
                    stamp = cam.clap_ns if stamp is None else stamp
                    period = cam.period_ns
            out.append({"name": name, "clap_ns": int(stamp) if stamp is not None else None,
                        "residual_ns": int(res[0]), "residuals_ns": [int(r) for r in res],
                        "period_ns": int(period)})
        return out

    def to_dict(self) -> dict:
        """The ``speechcal sync`` JSON document (DESIGN.md §2) plus detail keys."""
        doc = {
            "offset_ns": self.model.offset_ns,
            "drift": self.model.drift,
            "drift_ppm": round(self.model.drift * 1e6, 3) + 0.0,  # never -0.0
            "source": self.model.source,
            "claps": [{"audio_s": c.audio_s, "session_ns": c.session_ns,
                       "audio_source": c.audio_source, "video_source": c.video_source,
                       "cameras": [{"name": k.name, "clap_ns": k.clap_ns, "method": k.method,
                                    "frame_index": k.frame_index} for k in c.cameras]}
                      for c in self.claps],
            "cameras": self.residuals(),
            "warnings": list(self.warnings),
        }
        doc.update(self.extra)
        return doc


def model_from_claps(claps: list[Clap] | tuple[Clap, ...], source: str = "auto") -> SyncModel:
    """Offset from the first clap; drift from the first and last when there are two or more."""
    if not claps:
        raise ValueError("at least one clap is needed")
    ordered = sorted(claps, key=lambda c: c.audio_s)
    first, last = ordered[0], ordered[-1]
    drift = 0.0
    if len(ordered) >= 2 and last.audio_s - first.audio_s > 1.0:
        drift = _pair_drift(first, last)
    offset = first.session_ns - round(first.audio_s * (1.0 + drift) * 1e9)
    return SyncModel(int(offset), float(drift), source)


def _pair_drift(first: Clap, last: Clap) -> float:
    """Drift from two claps, camera by camera where a camera saw both (its offset cancels),
    each counted by the inverse variance of its time between them."""
    da = last.audio_s - first.audio_s
    spans = _camera_spans(first, last)
    if spans is not None:
        ds, var, _ = spans
        w = 1.0 / var
        return float(np.sum(w * ds) / np.sum(w)) / (da * 1e9) - 1.0
    return (last.session_ns - first.session_ns) / (da * 1e9) - 1.0


def _camera_spans(first: Clap, last: Clap
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Per camera that saw both claps: the session time between them (ns), its variance
    (ns², its two clap timings' :func:`timing_sd_ns` squared) and whether V fits measured
    both timings, of three cameras or more those near the median; None when the claps
    were set on the session clock by hand or no camera saw both."""
    if first.session_override_ns is not None or last.session_override_ns is not None:
        return None
    both = {c.name: c for c in first.cameras}
    pairs = [(both[c.name], c) for c in last.cameras if c.name in both]
    if not pairs:
        return None
    ds = np.array([b.clap_ns - a.clap_ns for a, b in pairs], dtype=np.float64)
    var = np.array([timing_sd_ns(a) ** 2 + timing_sd_ns(b) ** 2 for a, b in pairs])
    measured = np.array([_fit_timed(a) and _fit_timed(b) for a, b in pairs])
    if ds.size >= 3:
        keep = np.abs(ds - np.median(ds)) <= 3 * _mad(ds) + 2e6
        ds, var, measured = ds[keep], var[keep], measured[keep]
    return ds, var, measured


def _fit_timed(cam: CameraClap) -> bool:
    return cam.method == "v-fit" and cam.sigma_ns > 0


def timing_sd_ns(cam: CameraClap) -> float:
    """How well a camera timed a clap (ns): its V fit's standard error (at least
    MIN_TIMING_SD_NS), else, timed to a frame or set by hand, its frame period over
    sqrt(12) (a faster camera times the clap better; no period known: as 30 fps)."""
    if _fit_timed(cam):
        return float(max(cam.sigma_ns, MIN_TIMING_SD_NS))
    return max(cam.period_ns or 33_333_333, 1) / np.sqrt(12.0)


def drift_notes(claps: list[Clap] | tuple[Clap, ...], model: SyncModel,
                audio_s: float | None = None) -> list[str]:
    """Notes when two claps' drift rests on weak evidence: cameras that disagree on the time
    between the claps beyond their timing errors, or a drift whose standard error, carried
    to the audio farthest from the first clap (``audio_s``: the audio's length; unknown:
    the last clap), moves it more than DOUBTFUL_SHIFT_S. Only the cameras whose V fits
    gave their timing errors count (a clap timed to a frame or set by hand has none)."""
    ordered = sorted(claps, key=lambda c: c.audio_s)
    if len(ordered) < 2 or model.drift == 0.0:
        return []
    first, last = ordered[0], ordered[-1]
    spans = _camera_spans(first, last)
    if spans is None:
        return []
    ds, var, measured = spans
    ds, var = ds[measured], var[measured]
    if ds.size == 0:
        return []
    da = last.audio_s - first.audio_s
    notes = []
    if ds.size >= 2:
        gap = float(np.ptp(ds))
        i, j = int(np.argmin(ds)), int(np.argmax(ds))
        if gap > DISAGREE_NS and gap > 3.0 * float(np.sqrt(var[i] + var[j])):
            notes.append(f"the cameras disagree on the time between the claps by "
                         f"{gap / 1e6:.1f} ms ({gap / (da * 1e9) * 1e6:.0f} ppm of drift), "
                         "more than their clap timings allow: check both claps in the review")
    sd = float(np.sqrt(1.0 / np.sum(1.0 / var))) / (da * 1e9)
    reach_s = max(first.audio_s, (audio_s or last.audio_s) - first.audio_s)
    if sd * reach_s > DOUBTFUL_SHIFT_S:
        notes.append(f"drift {model.drift * 1e6:.0f} ppm is uncertain by about "
                     f"{sd * 1e6:.0f} ppm ({sd * reach_s * 1e3:.0f} ms at the words farthest "
                     f"from the first clap): the claps are {da:.0f} s apart and timed to "
                     f"{float(np.sqrt(np.min(var))) / 1e6:.1f} ms at best; clap again, "
                     "in clear view, farther apart")
    return notes


def timing_weight(period_ns: int | None) -> float:
    """How much a camera's clap time counts: inverse frame period squared (a 30 fps
    camera counts four times a 15 fps one; no period known: as 30 fps)."""
    return 1.0 / max(period_ns or 33_333_333, 1) ** 2


def _mad(v: np.ndarray) -> float:
    return float(1.4826 * np.median(np.abs(v - np.median(v))))


def build_result(claps: list[Clap], warnings: list[str] | None = None,
                 extra: dict | None = None) -> SyncResult:
    """A result from claps; the source is "manual" when any clap was edited. The audio's
    length, for the drift's notes, is read from ``extra["audio"]["duration_s"]``."""
    source = "manual" if any(c.edited for c in claps) else "auto"
    ordered = tuple(sorted(claps, key=lambda c: c.audio_s))
    model = model_from_claps(ordered, source)
    notes = list(warnings or [])
    if abs(model.drift) > MAX_DRIFT:
        notes.append(f"drift {model.drift * 1e6:.0f} ppm is implausible; "
                     "check that both claps were matched (set them by hand)")
    else:
        audio = (extra or {}).get("audio") or {}
        notes.extend(drift_notes(ordered, model, audio.get("duration_s")))
    result = SyncResult(model, ordered, (), dict(extra or {}))
    cams = result.residuals()
    for cam in cams:
        notes.extend(_residual_warning(cam, len(cams)))
    return replace(result, warnings=tuple(dict.fromkeys(notes)))


def clap_off(cam: Mapping[str, Any]) -> bool:
    """Whether a camera's clap (an entry of :meth:`SyncResult.residuals`, as sessions store
    them) sits more than half a frame off the sync the claps give."""
    period = cam.get("period_ns") or 33_333_333
    return abs(cam.get("residual_ns") or 0) > period / 2


def clap_misread(cam: Mapping[str, Any]) -> bool:
    """Whether a camera's first clap sits more than half a frame off (:func:`clap_off`)
    while a later clap is in line: the first was timed wrongly, its clock is not off."""
    period = cam.get("period_ns") or 33_333_333
    later = (cam.get("residuals_ns") or [])[1:]
    return clap_off(cam) and any(abs(r) <= period / 2 for r in later)


def _residual_warning(cam: dict, cameras: int) -> list[str]:
    """A note for a camera whose clap sits more than half a frame off the others.

    Seen at two claps with the same offset, the camera's clock is off; in line at the
    other clap (of three cameras or more, whose median sets the offset), it timed the
    first clap wrongly and there is nothing to do; otherwise either, and the operator
    should look.
    """
    period = cam["period_ns"] or 33_333_333
    res = cam["residuals_ns"]
    if not clap_off(cam):
        return []
    head = f"{cam['name']}: clap {cam['residual_ns'] / 1e6:+.1f} ms off the other cameras"
    if len(res) >= 2 and max(res) - min(res) < period / 4:
        return [f"{head} at both claps; its clock is off by that much"]
    if clap_misread(cam) and cameras >= 3:  # two cameras apart: which one is wrong?
        return [f"{head} at the first clap but in line at the second: it did not time the "
                "first clap well, its clock is right; the other cameras set the offset, "
                "nothing to do"]
    return [f"{head}; its clock may be off, or its clap was not seen clearly "
            "(check the clap in the review)"]
