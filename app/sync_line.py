"""What the offset line under the waveform says: where the audio starts, drift, how the
offset was found and what looks wrong, with shorter forms for a narrow window."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from speechcal_core.sync.estimate import clap_misread, clap_off
from speechcal_core.text import WARNING_SYMBOL

if TYPE_CHECKING:
    from speechcal_core.frames.word_stillness import WordStillness
    from speechcal_core.session.model import Session

#: the line's tooltip when few words fall at a still board (see word_stillness)
MOVING_WORDS_TIP = (
    "The board is held still at each trigger word, yet here many words fall while it "
    "moves. Is the audio this recording's? If it is, the offset is off: another sound "
    "may have been taken for the clap. Find the real clap on the waveform (the wheel "
    "zooms out to the whole audio: it may lie before the first frame), click it and "
    "press C; or move the audio with { } (±1 frame) until the words fall where the "
    "board stops.")
#: how the offset was found, as the line says it ("assumed": the audio taken to start
#: with the first frame, no clap found; it said "edited ✎" before anyone edited it)
HOW = {"auto": "auto ✓", "manual": "edited ✎", "stamped": "stamped ✓",
       "assumed": "assumed, not measured"}


@dataclass(frozen=True)
class SyncLine:
    """The line's forms, longest first (a narrow window shows the longest that fits),
    whether it warns (amber), and its tooltip (the longest form and the notes behind a
    warning)."""

    texts: tuple[str, ...]
    alerted: bool
    tooltip: str


def audio_start_text(lead_s: float, short: bool = False) -> str:
    """Where the audio starts against the first frame, ``lead_s`` seconds before it
    (negative: after it), in words with no sign: "audio starts 1.183 s after the first
    frame" ("audio 1.183 s after 1st frame" ``short``); "with" when that is under half a
    millisecond."""
    lead_ms = round(lead_s * 1000)
    starts, first = ("audio", "1st frame") if short else ("audio starts", "the first frame")
    if lead_ms == 0:
        return f"{starts} with {first}"
    side = "before" if lead_ms > 0 else "after"
    return f"{starts} {abs(lead_ms) / 1000:.3f} s {side} {first}"


def _camera_alerts(cams: list[dict[str, Any]],
                   shown: bool) -> tuple[list[str], list[str], list[dict[str, Any]]]:
    """The cameras whose clap sits off the others, in words and shorter; and those that
    timed the first clap wrongly but the second well (their clock is right: with three or
    more cameras the others set the offset)."""
    misread = [c for c in cams if len(cams) >= 3 and clap_misread(c)]
    off = [c for c in cams if shown and clap_off(c) and c not in misread]
    says = [f"{c.get('name')} clap {(c.get('residual_ns') or 0) / 1e6:+.1f} ms off" for c in off]
    return [f"{s} the others" for s in says], says, misread


def sync_line_forms(session: Session, first_frame_ns: int, stillness: WordStillness) -> SyncLine:
    """The offset line of ``session`` whose first frame is at ``first_frame_ns``: in
    amber and first, what looks wrong (a camera's clap off the others, words that fall
    while the board moves), so that shorter forms shorten the rest, not that."""
    sync = session.sync
    lead = (first_frame_ns - sync.offset_ns) / 1e9
    how = HOW.get(sync.source, sync.source)
    cams = [c for c in session.sync_evidence.get("cameras") or [] if isinstance(c, dict)]
    # the residuals are the automatic sync's: an edited offset has none to show
    shown = bool(cams) and sync.source != "manual"
    alerts, short_alerts, misread = _camera_alerts(cams, shown)
    off = bool(alerts)
    notes = [str(w) for w in session.sync_evidence.get("warnings") or []] \
        if alerts or misread else []
    residuals = [abs(c.get("residual_ns") or 0) for c in cams if c not in misread]
    if stillness.doubtful:
        alerts.insert(0, f"only {stillness.still} of {stillness.judged} words at a still "
                         "board")
        short_alerts.insert(0, f"only {stillness.still}/{stillness.judged} words at a "
                               "still board")
        notes.insert(0, MOVING_WORDS_TIP)
    # one camera has nothing to differ from; one clap measures no drift
    worst = f"≤ {max(residuals) / 1e6:.1f} ms" \
        if shown and residuals and not off and len(cams) > 1 else ""
    claps = session.sync_evidence.get("claps") or []
    # an offset given (process --offset-ns) has no clap at all: "(one clap)" misled
    few = "one clap" if claps else "no clap"
    unmeasured = len(claps) < 2 and sync.drift == 0
    # + 0.0: a drift under 0.05 ppm below zero (a stamped topic's slope: -2e-16) said
    # "-0.0 ppm", as if the microphone ran slow
    drift = f"drift {round(sync.drift * 1e6, 1) + 0.0:.1f} ppm"
    forms = [
        [audio_start_text(lead), f"drift not measured ({few})" if unmeasured else drift,
         how, f"camera residuals {worst}" if worst else ""],
        [audio_start_text(lead), f"no drift ({few})" if unmeasured else drift, how,
         f"residuals {worst}" if worst else ""],
        [audio_start_text(lead, short=True), few if unmeasured else drift, how,
         f"residuals {worst}" if worst else ""],
    ]
    texts = [" · ".join(part for part in form if part) for form in forms]
    if alerts:
        lead_in = f"{WARNING_SYMBOL} {' · '.join(alerts)}"
        short_in = f"{WARNING_SYMBOL} {' · '.join(short_alerts)}"
        texts = [*(f"{lead_in} · {t}" for t in texts), f"{short_in} · {texts[-1]}", short_in]
    texts = list(dict.fromkeys(texts))  # forms that came out alike, once
    return SyncLine(tuple(texts), bool(alerts), "\n".join([texts[0], *notes]))
