"""Header-stamp index and random frame access on big 3-camera bags, against plain reads.

Writes the bags into a temporary folder (deleted afterwards), evicts their pages with
``posix_fadvise(DONTNEED)`` before every measurement and runs each measurement in a fresh
process, so ``ru_inblock`` (512-byte blocks read from disk) and peak RSS belong to it alone.

    python benchmarks/bench_index.py              # >= 2 GB per bag (issue 3 targets)
    python benchmarks/bench_index.py --quick      # 0.25 GB per bag
    python benchmarks/bench_index.py --size-gb 5  # peak-RSS check on a 5 GB bag

Prints figures and ratios; asserts nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

WIDTH, HEIGHT, CAMS, RATE_NS = 1280, 720, 3, 33_333_333
T0 = 1_700_000_000_000_000_000


# -- data ----------------------------------------------------------------------------------


def _pixels(cam: int) -> np.ndarray:
    """A textured 1280x720 BGR frame (gradient, blocks and noise) per camera."""
    rng = np.random.default_rng(cam)
    y, x = np.mgrid[0:HEIGHT, 0:WIDTH]
    base = ((x // 40 + y // 40) % 2 * 120 + x * 60 // WIDTH + cam * 30).astype(np.int16)
    noise = rng.integers(-6, 7, (HEIGHT, WIDTH), dtype=np.int16)
    img = np.clip(base + noise, 0, 255).astype(np.uint8)
    return np.dstack([img, np.roll(img, 7, axis=1), np.roll(img, 13, axis=0)])


def _templates(ros1: bool, jpeg: bool) -> list[bytearray]:
    import cv2
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    header_t, time_t = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    out = []
    for cam in range(CAMS):
        kw = {"seq": 0} if ros1 else {}
        header = header_t(**kw, stamp=time_t(sec=0, nanosec=0), frame_id=f"cam{cam}")
        img = _pixels(cam)
        if jpeg:
            jpg = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 90])[1]
            data = np.frombuffer(jpg, np.uint8)
            msg = ts.types["sensor_msgs/msg/CompressedImage"](header, "jpeg", data)
            msgtype = "sensor_msgs/msg/CompressedImage"
        else:
            msg = ts.types["sensor_msgs/msg/Image"](
                header, HEIGHT, WIDTH, "bgr8", 0, WIDTH * 3, img.reshape(-1)
            )
            msgtype = "sensor_msgs/msg/Image"
        ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
        out.append(bytearray(ser(msg, msgtype)))
    return out


def write_bag(path: Path, fmt: str, size_bytes: int, *, jpeg: bool = False) -> Path:
    """Write a 3-camera bag of about ``size_bytes`` in fmt (ros1, ros1-lz4, ros2-sqlite3...)."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    ros1 = fmt.startswith("ros1")
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    templates = _templates(ros1, jpeg)
    n = max(2, size_bytes // sum(len(t) for t in templates))
    if ros1:
        writer: Writer1 | Writer2 = Writer1(path)
        if fmt != "ros1":
            writer.set_compression(Writer1.CompressionFormat[fmt.split("-")[1].upper()])
    else:
        plugin = StoragePlugin.MCAP if fmt.startswith("ros2-mcap") else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
        if fmt == "ros2-mcap-zstd":
            from rosbags.rosbag2 import CompressionFormat, CompressionMode

            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    msgtype = "sensor_msgs/msg/CompressedImage" if jpeg else "sensor_msgs/msg/Image"
    with writer:
        conns = [
            writer.add_connection(f"/cam{k}/image_raw", msgtype, typestore=ts) for k in range(CAMS)
        ]
        for i in range(n):
            for cam in range(CAMS):
                stamp = T0 + i * RATE_NS + cam * 1_000_000
                msg = templates[cam]
                if ros1:
                    struct.pack_into("<III", msg, 0, i, stamp // 10**9, stamp % 10**9)
                else:
                    struct.pack_into("<iI", msg, 4, stamp // 10**9, stamp % 10**9)
                writer.write(conns[cam], stamp + 2_000_000, bytes(msg))  # type: ignore[arg-type]
    return path


def data_files(path: Path) -> list[Path]:
    """The files holding a recording's bytes."""
    if path.is_dir():
        return sorted(p for p in path.iterdir() if p.suffix in (".db3", ".mcap"))
    return [path]


def evict(path: Path) -> None:
    """Drop the recording's pages from the page cache (flushing them first)."""
    for f in data_files(path):
        fd = os.open(f, os.O_RDONLY)
        try:
            os.fsync(fd)
            os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
        finally:
            os.close(fd)


def drop_index_cache(path: Path) -> None:
    """Remove cached indexes so the next open builds one."""
    for f in data_files(path):
        for c in f.parent.glob(f".{f.name}.speechcal-index.npz"):
            c.unlink()


# -- workers (each in its own process) ------------------------------------------------------


_INBLOCK0 = 0


def _start() -> float:
    """Reset the disk-read counter (imports done) and return the start time."""
    global _INBLOCK0
    _INBLOCK0 = resource.getrusage(resource.RUSAGE_SELF).ru_inblock
    return time.perf_counter()


def _usage() -> dict[str, float]:
    ru = resource.getrusage(resource.RUSAGE_SELF)
    return {"inblock_bytes": (ru.ru_inblock - _INBLOCK0) * 512, "peak_rss_mb": ru.ru_maxrss / 1024}


def worker(kind: str, path: Path, extra: str) -> dict[str, object]:
    """Run one measurement in this process and return its figures."""
    if kind == "seq":
        t = _start()
        total = 0
        for f in data_files(path):
            with f.open("rb", buffering=0) as fh:
                while block := fh.read(8 << 20):
                    total += len(block)
        return {"seconds": time.perf_counter() - t, "bytes": total, **_usage()}
    if kind == "rosbags":
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore

        t = _start()
        count = 0
        store = get_typestore(Stores.ROS2_HUMBLE)
        with AnyReader([path], default_typestore=store) as reader:
            for conn, _, raw in reader.messages():
                msg = reader.deserialize(raw, conn.msgtype)
                count += msg.header.stamp.sec > 0
        return {"seconds": time.perf_counter() - t, "messages": count, **_usage()}
    import speechcal_core.sources.bag_source
    import speechcal_core.sources.mcap
    import speechcal_core.sources.rosbag1
    import speechcal_core.sources.rosbag2  # noqa: F401 - imports outside the timed part
    from speechcal_core.sources import open_recording

    if kind in ("ours", "ours-cached"):
        t = _start()
        with open_recording([path], use_cache=kind == "ours-cached") as src:
            count = sum(s.count for s in src.streams)
        return {"seconds": time.perf_counter() - t, "frames": count, **_usage()}
    if kind == "random":
        n = int(extra)
        with open_recording([path]) as src:
            streams = [(s.name, s.count) for s in src.streams]
            rng = np.random.default_rng(1)
            times = []
            for _ in range(n):
                name, count = streams[int(rng.integers(len(streams)))]
                i = int(rng.integers(count))
                t = time.perf_counter()
                img = src.frame(name, i)
                times.append(time.perf_counter() - t)
                assert img.shape == (HEIGHT, WIDTH, 3)
        ms = np.array(times) * 1000
        return {
            "p50_ms": float(np.percentile(ms, 50)),
            "p95_ms": float(np.percentile(ms, 95)),
            "max_ms": float(ms.max()),
            **_usage(),
        }
    raise SystemExit(f"unknown worker {kind}")


def run_worker(kind: str, path: Path, extra: str = "") -> dict[str, object]:
    """Evict the recording's pages, then measure in a fresh interpreter."""
    evict(path)
    cmd = [sys.executable, __file__, "--worker", kind, str(path), extra]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def run_cli(path: Path) -> float:
    """Wall time of ``speechcal index --no-cache --json``, interpreter start included."""
    evict(path)
    exe = Path(sys.executable).with_name("speechcal")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "speechcal_core.cli"]
    t = time.perf_counter()
    cmd += ["index", "--no-cache", "--json", str(path)]
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t


# -- report -------------------------------------------------------------------------------


def _mb(n: object) -> str:
    return f"{float(n) / 1e6:9.1f} MB"  # type: ignore[arg-type]


def bench_bag(path: Path, fmt: str, *, rosbags_pass: bool, random_n: int) -> None:
    """Print index figures for one bag beside the plain read and the rosbags pass."""
    size = sum(f.stat().st_size for f in data_files(path))
    print(f"\n== {fmt}: {size / 1e9:.2f} GB, {CAMS} cameras {WIDTH}x{HEIGHT}")
    seq_first = run_worker("seq", path)  # right after writing: the disk may still be busy
    drop_index_cache(path)
    ours = run_worker("ours", path)
    cached = run_worker("ours-cached", path)
    drop_index_cache(path)
    cli = run_cli(path)
    rows = [
        ("(b) sequential read, first", seq_first),
        ("our index, --no-cache", ours),
        ("our index, cached", cached),
    ]
    if rosbags_pass:
        rows.insert(1, ("(a) rosbags deserialize all", run_worker("rosbags", path)))
    seq_again = run_worker("seq", path)
    rows.insert(1, ("(b) sequential read, again", seq_again))
    # ratios against the faster of the two plain reads (the harder comparison for us)
    seq = min(seq_first, seq_again, key=lambda r: float(r["seconds"]))  # type: ignore[arg-type]
    print(f"{'':30} {'seconds':>9} {'read from disk':>14} {'of file':>8} {'peak RSS':>10}")
    for label, r in rows:
        secs = float(r["seconds"])  # type: ignore[arg-type]
        inb = float(r["inblock_bytes"])  # type: ignore[arg-type]
        print(
            f"{label:30} {secs:9.3f} {_mb(inb):>14} {100 * inb / size:7.2f}% "
            f"{float(r['peak_rss_mb']):7.0f} MB"  # type: ignore[arg-type]
        )
    seq_s, ours_s = float(seq["seconds"]), float(ours["seconds"])  # type: ignore[arg-type]
    print(f"{'speechcal index --no-cache (CLI)':30} {cli:9.3f}   (interpreter start included)")
    print("ratios use the faster sequential read")
    print(f"ratio sequential read / our index (in-process): {seq_s / ours_s:8.1f}x")
    print(f"ratio sequential read / CLI run:                {seq_s / cli:8.1f}x")
    print(f"ratio our index / sequential read:              {ours_s / seq_s:8.2f}")
    if rosbags_pass:
        ros_s = float(rows[2][1]["seconds"])  # type: ignore[arg-type]
        print(f"ratio rosbags pass / our index:                 {ros_s / ours_s:8.1f}x")
    if random_n:
        cold = run_worker("random", path, str(random_n))
        print(
            f"random frame access ({random_n} frames, pages evicted first): "
            f"p50 {cold['p50_ms']:.1f} ms, p95 {cold['p95_ms']:.1f} ms, max {cold['max_ms']:.1f} ms"
        )


def main() -> None:
    """Generate, measure, print, clean up."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size-gb", type=float, default=2.1, help="size of each raw bag (GB)")
    ap.add_argument("--quick", action="store_true", help="small run (0.25 GB per bag)")
    ap.add_argument(
        "--formats",
        default="ros1,ros2-sqlite3,ros1-lz4",
        help="comma-separated: ros1, ros1-bz2, ros1-lz4, ros2-sqlite3, ros2-mcap, ros2-mcap-zstd",
    )
    ap.add_argument("--dir", default=None, help="where to write the temporary bags")
    ap.add_argument("--random", type=int, default=200, help="frames for the random-access test")
    ap.add_argument("--keep", action="store_true", help="keep the generated bags")
    ap.add_argument("--worker", nargs=3, metavar=("KIND", "PATH", "EXTRA"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        kind, path, extra = args.worker
        print(json.dumps(worker(kind, Path(path), extra)))
        return
    size = int((0.25 if args.quick else args.size_gb) * 1e9)
    tmp = Path(tempfile.mkdtemp(prefix="speechcal-bench-", dir=args.dir))
    print(f"bags in {tmp} (deleted afterwards unless --keep); {os.cpu_count()} CPUs")
    try:
        for fmt in args.formats.split(","):
            t = time.perf_counter()
            name = f"raw_{fmt}" + (".bag" if fmt.startswith("ros1") else "")
            path = write_bag(tmp / name, fmt, size)
            print(f"\n(wrote {fmt} in {time.perf_counter() - t:.0f} s)")
            bench_bag(path, fmt, rosbags_pass=True, random_n=args.random)
            if not args.keep:
                shutil.rmtree(path) if path.is_dir() else path.unlink()
        jpeg = write_bag(tmp / "jpeg.bag", "ros1", min(size, 300_000_000), jpeg=True)
        print("\n== JPEG (CompressedImage) random access")
        r = run_worker("random", jpeg, str(args.random))
        print(
            f"random frame access ({args.random} frames, pages evicted first): "
            f"p50 {r['p50_ms']:.1f} ms, p95 {r['p95_ms']:.1f} ms, max {r['max_ms']:.1f} ms"
        )
    finally:
        if not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
