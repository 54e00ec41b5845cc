"""The "blurred" flag on still and on moving frames: session-relative against still-relative.

On seeded synthetic sessions (rendered on demand, no files; JPEG round trip as ``synth``
writes frames) of several kinds, in the same run on the same frames:

- per frame: every camera's frame nearest the middle and the first quarter of every hold
  (``still``: its whole exposure inside the hold) and nearest 40 % and 60 % into every move
  (``moving``, motion-blurred), each judged as the chosen frame of a search window around
  it as the pipeline scans one (-0.3 s, +0.7 s);
- per chosen frame: the pipeline's frame sets for the session's trigger words, each
  chosen frame still or moving by the truth.

Baseline ``old``: raw sharpness over the 90th percentile of the camera's still frames
(per frame) or of its chosen frames (pipeline), flagged under 0.25, as the flag was.
``new``: :func:`speechcal_core.frames.sets._still_relative` (relative to the sharpest frame
of the nearest still stretch of the same window; at full size for a moving frame) under
``BLURRED_BELOW``; with no still frame in the window, the old figure under
``BLURRED_BELOW_SESSION``.

    python benchmarks/bench_blur_flag.py                  # five kinds, 30 s each
    python benchmarks/bench_blur_flag.py --kinds 4cam-2fish --duration 20

Prints flagged / total per kind and frame kind; asserts nothing.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np

REPO = Path(__file__).resolve().parents[1]
for path in (REPO, REPO / "tests" / "frames"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from rendered_source import RenderedSource  # noqa: E402

from speechcal_core.frames.detect import TargetDetector  # noqa: E402
from speechcal_core.frames.preview import preview_factor, preview_gray  # noqa: E402
from speechcal_core.frames.quality import mask_box, region_mask, sharpness  # noqa: E402
from speechcal_core.frames.select import score_camera  # noqa: E402
from speechcal_core.frames.sets import (  # noqa: E402
    BLURRED_BELOW,
    BLURRED_BELOW_SESSION,
    FrameSetOptions,
    _still_reference,
    _still_relative,
    build_frame_sets,
)
from speechcal_core.frames.window import scan_window  # noqa: E402
from speechcal_core.session.model import Trigger  # noqa: E402
from speechcal_core.synth.image_messages import JPEG_QUALITY  # noqa: E402
from speechcal_core.synth.options import SynthOptions  # noqa: E402
from speechcal_core.synth.timeline import Timeline, plan_session  # noqa: E402

NS = 1_000_000_000
OLD_BELOW = 0.25
KINDS = {
    "3pin-640": {"cameras": 3, "seed": 1},
    "4cam-2fish": {"cameras": 4, "fisheye": 2, "seed": 3},
    "3pin-800x600-rs": {"cameras": 3, "width": 800, "height": 600, "rolling_shutter": True,
                        "seed": 5},
    "5cam-640x400-rs": {"cameras": 5, "width": 640, "height": 400, "rolling_shutter": True,
                        "seed": 8},
    "2cam-1fish-960": {"cameras": 2, "fisheye": 1, "width": 960, "height": 600, "seed": 11},
}


class JpegSource(RenderedSource):
    """Rendered frames passed through JPEG as ``synth`` stores them."""

    def frame(self, stream: str, i: int) -> np.ndarray:
        _ok, buf = cv2.imencode(".jpg", super().frame(stream, i),
                               [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
        return cv2.imdecode(buf, cv2.IMREAD_COLOR)


def raw_sharpness(source: RenderedSource, stream: str, i: int,
                  det: TargetDetector) -> float | None:
    """Full-resolution sharpness over the detected target, as the pipeline measures it."""
    img = preview_gray(source, stream, i, 1, False)
    found = det.detect(img)
    if found is None:
        return None
    mask = region_mask(img.shape[:2], [found.hull()], 0)
    rows, cols = mask_box(mask)
    return sharpness(img[rows, cols], mask[rows, cols])


def is_still(tl: Timeline, source: RenderedSource, c: int, i: int) -> bool:
    """Whether camera ``c``'s frame ``i`` was exposed wholly inside one hold."""
    cam = tl.cameras[c]
    t = int(source.true_ns(cam.name)[i])
    half = int((cam.exposure_s + cam.rolling_shutter_s) * NS / 2) + 2_000_000
    a, b = tl.segment_at(t - half), tl.segment_at(t + half)
    return a is b and a.is_hold


def per_frame(tl: Timeline, source: RenderedSource, det: TargetDetector) -> list[dict]:
    """Old and new figures of still and moving frames, each chosen in a window around it."""
    detector = TargetDetector(tl.target)
    holds = [s for s in tl.segments if s.kind == "hold"]
    moves = [s for s in tl.segments if s.kind == "move"]
    times = [("still", s.start_ns + (s.end_ns - s.start_ns) * f) for s in holds
             for f in (0.5, 0.25)]
    times += [("moving", s.start_ns + (s.end_ns - s.start_ns) * f) for s in moves
              for f in (0.4, 0.6)]
    items = []
    for kind, t in times:
        for c, cam in enumerate(tl.cameras):
            info = source.streams[c]
            stamps = source.stamps(cam.name)
            i = int(np.argmin(np.abs(source.true_ns(cam.name) - t)))
            if (kind == "still") != is_still(tl, source, c, i):
                continue
            stride = max(1, round(NS / FrameSetOptions().scan_rate_hz / info.median_period_ns))
            win = scan_window(source, cam.name, stamps, int(stamps[i]) - int(0.3 * NS),
                              int(stamps[i]) + int(0.7 * NS), detector=detector,
                              factor=preview_factor(cam.width, cam.height, 320),
                              detect_factor=preview_factor(cam.width, cam.height, 640),
                              compressed=False, period_ns=info.median_period_ns,
                              stride=stride)
            items.append((kind, c, i, win))
    floors = {}
    for c in range(len(tl.cameras)):
        wins = [w for _k, cc, _i, w in items if cc == c]
        vals = np.concatenate([w.motion[w.inside & ~w.bad & np.isfinite(w.motion)]
                               for w in wins])
        vals = vals[vals > 0]
        floors[c] = float(np.percentile(vals, 10)) if vals.size else 0.0
    rows = []
    for kind, c, i, win in items:
        name = tl.cameras[c].name
        p = int(np.argmin(np.abs(win.indices - i)))
        score = score_camera(win, floors[c])
        raw = raw_sharpness(source, name, int(win.indices[p]), det)
        q = _still_reference(win, score, p)
        ref = raw_sharpness(source, name, int(win.indices[q]), det) \
            if q is not None and not score.still[p] else None
        rows.append({"kind": kind, "cam": c, "raw": raw,
                     "local": _still_relative(win, score, p, raw, ref)})
    for c in range(len(tl.cameras)):
        ref = np.percentile([r["raw"] for r in rows if r["cam"] == c and r["kind"] == "still"
                             and r["raw"] is not None], 90)
        for r in rows:
            if r["cam"] == c and r["raw"] is not None:
                r["old"] = r["raw"] / ref
    return rows


def pipeline(tl: Timeline, source: RenderedSource, det: TargetDetector) -> list[dict]:
    """Old and new figures of the frames the pipeline chooses for the trigger words."""
    triggers = []
    for slot in tl.speech:
        if slot.kind != "trigger":
            continue
        end = slot.anchor_ns if slot.align == "end" else slot.anchor_ns + NS // 4
        end_s = float(tl.sync.to_audio(end))
        triggers.append(Trigger("capture", end_s - 0.5, end_s))
    result = build_frame_sets(source, tl.sync, triggers, tl.target, FrameSetOptions(workers=2))
    assert result.references is not None
    rows = []
    for fs in result.sets:
        for f in fs.frames:
            if f.index < 0 or f.sharpness is None:
                continue
            c = next(k for k, cam in enumerate(tl.cameras) if cam.name == f.stream)
            raw = raw_sharpness(source, f.stream, f.index, det)
            ref = result.references.sharpness[f.stream]
            rows.append({"kind": "still" if is_still(tl, source, c, f.index) else "moving",
                         "old_flag": raw is not None and ref > 0 and raw / ref < OLD_BELOW,
                         "new_flag": "blurred" in f.flags, "new": f.sharpness,
                         "old": raw / ref if raw is not None and ref > 0 else None})
    return rows


def counts(rows: list[dict], kind: str, flag: str) -> str:
    sel = [r for r in rows if r["kind"] == kind]
    return f"{sum(bool(r[flag]) for r in sel)}/{len(sel)}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kinds", default=",".join(KINDS), help="comma-separated")
    parser.add_argument("--duration", type=float, default=30.0)
    args = parser.parse_args()
    total: dict[str, list[dict]] = {"frame": [], "chosen": []}
    for name in args.kinds.split(","):
        tl = plan_session(SynthOptions(duration=args.duration, **KINDS[name]))
        source = JpegSource(tl)
        det = TargetDetector(tl.target)
        frames = [r for r in per_frame(tl, source, det) if r["raw"] is not None]
        for r in frames:
            r["old_flag"] = r["old"] < OLD_BELOW
            r["new_flag"] = (r["local"] < BLURRED_BELOW if r["local"] is not None
                             else r["old"] < BLURRED_BELOW_SESSION)
            r["fallback"] = r["local"] is None
        chosen = pipeline(tl, source, det)
        total["frame"] += frames
        total["chosen"] += chosen
        report(name, frames, chosen)
    report("all", total["frame"], total["chosen"])


def report(name: str, frames: list[dict], chosen: list[dict]) -> None:
    still = [r["old"] for r in frames if r["kind"] == "still"]
    local = [r["local"] for r in frames if r["kind"] == "still" and r["local"] is not None]
    moving_fb = [r for r in frames if r["kind"] == "moving" and r["fallback"]]
    print(f"{name}:")
    print(f"  per frame  still flagged  old {counts(frames, 'still', 'old_flag'):>7}  "
          f"new {counts(frames, 'still', 'new_flag'):>7}   "
          f"moving caught  old {counts(frames, 'moving', 'old_flag'):>7}  "
          f"new {counts(frames, 'moving', 'new_flag'):>7}  "
          f"(no still frame in window: old {sum(r['old_flag'] for r in moving_fb)}"
          f"/{len(moving_fb)}, new {sum(r['new_flag'] for r in moving_fb)}/{len(moving_fb)})")
    moving = np.array([r["local"] for r in frames
                       if r["kind"] == "moving" and r["local"] is not None])
    sweep = "  ".join(f"<{t:.1f}: {int((moving < t).sum())}" for t in (0.4, 0.5, 0.6, 0.7, 0.8))
    print(f"             still figure  old {min(still):.2f}-{max(still):.2f}  "
          f"new {min(local):.2f}-{max(local):.2f}   "
          f"new figure of {moving.size} moving frames with a still stretch: {sweep}")
    print(f"  chosen     still flagged  old {counts(chosen, 'still', 'old_flag'):>7}  "
          f"new {counts(chosen, 'still', 'new_flag'):>7}   "
          f"moving caught  old {counts(chosen, 'moving', 'old_flag'):>7}  "
          f"new {counts(chosen, 'moving', 'new_flag'):>7}")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
