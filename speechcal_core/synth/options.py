"""Validated options of a synthetic session (``speechcal synth``)."""

from __future__ import annotations

from dataclasses import dataclass

from speechcal_core.errors import UsageError

FORMATS = ("ros1", "ros2-sqlite3", "ros2-mcap")
RAW_ENCODINGS = ("mono8", "bgr8", "rgb8", "mono16", "bayer_rggb8")
COMPRESSED_ENCODINGS = ("jpeg", "png")
ENCODINGS = RAW_ENCODINGS + COMPRESSED_ENCODINGS


@dataclass(frozen=True)
class SynthOptions:
    """Everything that shapes a synthetic session; equal options + seed give equal output."""

    cameras: int = 3
    fisheye: int = 0
    duration: float = 60.0
    triggers: int | None = None
    trigger_word: str = "capture"
    snr_db: float = 20.0
    claps: int = 1
    drift_ppm: float = 5.0
    format: str = "ros1"
    encoding: str = "jpeg"
    seed: int = 0
    width: int = 640
    height: int = 480
    target_kind: str = "aprilgrid"
    ros1_compression: str = "none"  # none | bz2 | lz4
    rolling_shutter: bool = False

    def __post_init__(self) -> None:
        if not 1 <= self.cameras <= 12:
            raise UsageError(f"--cameras must be between 1 and 12, got {self.cameras}")
        if not 0 <= self.fisheye <= self.cameras:
            raise UsageError(f"--fisheye must be between 0 and --cameras ({self.cameras})")
        if not 5.0 <= self.duration <= 3600.0:
            raise UsageError(f"--duration must be between 5 and 3600 seconds, got {self.duration}")
        if self.triggers is not None and self.triggers < 0:
            raise UsageError(f"--triggers must be 0 or more, got {self.triggers}")
        if self.seed < 0:  # numpy's SeedSequence takes none
            raise UsageError(f"--seed must be 0 or more, got {self.seed}")
        if self.claps not in (1, 2):
            raise UsageError(f"--claps must be 1 or 2, got {self.claps}")
        if not -200.0 <= self.drift_ppm <= 200.0:
            raise UsageError(f"--drift-ppm must be within +-200, got {self.drift_ppm}")
        if not -10.0 <= self.snr_db <= 60.0:
            raise UsageError(f"--snr must be between -10 and 60 dB, got {self.snr_db}")
        if self.format not in FORMATS:
            raise UsageError(f"unknown --format {self.format!r}; use one of {', '.join(FORMATS)}")
        if self.encoding not in ENCODINGS:
            raise UsageError(
                f"unknown --encoding {self.encoding!r}; use one of {', '.join(ENCODINGS)}"
            )
        if self.ros1_compression not in ("none", "bz2", "lz4"):
            raise UsageError(f"unknown ROS1 chunk compression {self.ros1_compression!r}")
        if self.target_kind not in ("aprilgrid", "checkerboard"):
            raise UsageError(f"unknown target {self.target_kind!r}")
        if self.width < 64 or self.height < 64:
            raise UsageError("images must be at least 64x64 pixels")
