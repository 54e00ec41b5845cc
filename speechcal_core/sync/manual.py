"""Manual clap edits: set or nudge a clap in audio or video; every edit makes a new result."""

from __future__ import annotations

from dataclasses import replace

from speechcal_core.sync.estimate import CameraClap, Clap, SyncResult, build_result

AUDIO_NUDGE_S = 0.001


def manual_sync(pairs: list[tuple[float, int]]) -> SyncResult:
    """A result from claps given by hand as (audio seconds, session ns) pairs."""
    if not pairs:
        raise ValueError("give at least one (audio_s, session_ns) clap")
    claps = [Clap(float(a), (), "manual", "manual", int(s)) for a, s in pairs]
    return build_result(claps)


def set_audio_clap(result: SyncResult, index: int, audio_s: float) -> SyncResult:
    """Move clap ``index`` to ``audio_s`` (audio seconds)."""
    return _edit(result, index, replace(result.claps[index], audio_s=float(audio_s),
                                        audio_source="manual"))


def set_video_clap(result: SyncResult, index: int, session_ns: int,
                   camera: str | None = None) -> SyncResult:
    """Put clap ``index`` at ``session_ns``: for one camera, or for all when camera is None."""
    clap = result.claps[index]
    if camera is None:
        edited = replace(clap, session_override_ns=int(session_ns), video_source="manual")
    else:
        cams = tuple(replace(c, clap_ns=int(session_ns), method="manual")
                     if c.name == camera else c for c in clap.cameras)
        if not any(c.name == camera for c in clap.cameras):
            cams = (*cams, CameraClap(camera, int(session_ns), method="manual"))
        edited = replace(clap, cameras=cams, video_source="manual")
    return _edit(result, index, edited)


def nudge_audio(result: SyncResult, index: int, steps: int = 1) -> SyncResult:
    """Move clap ``index`` by ``steps`` milliseconds in audio."""
    clap = result.claps[index]
    return set_audio_clap(result, index, clap.audio_s + steps * AUDIO_NUDGE_S)


def nudge_video(result: SyncResult, index: int, frames: int = 1,
                camera: str | None = None) -> SyncResult:
    """Move clap ``index`` by ``frames`` frame periods (one camera, or all of them)."""
    clap = result.claps[index]
    period = _period(clap, camera)
    if camera is None:
        return set_video_clap(result, index, clap.session_ns + frames * period)
    cam = next(c for c in clap.cameras if c.name == camera)
    return set_video_clap(result, index, cam.clap_ns + frames * period, camera)


def _period(clap: Clap, camera: str | None) -> int:
    periods = [c.period_ns for c in clap.cameras if c.period_ns and camera in (None, c.name)]
    return min(periods) if periods else 33_333_333


def _edit(result: SyncResult, index: int, clap: Clap) -> SyncResult:
    claps = list(result.claps)
    claps[index] = clap
    return build_result(claps, extra=result.extra)
