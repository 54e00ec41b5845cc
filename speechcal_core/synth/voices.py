"""The bundled bank of real-voice clips (trigger words and distractor speech)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import soundfile as sf

from speechcal_core.errors import UsageError
from speechcal_core.resources import resource


@dataclass(frozen=True)
class Clip:
    """One bundled recording; its bounds are the spoken part's start and end."""

    file: str  # relative to resources/voices
    text: str
    kind: str  # "trigger" | "distractor"
    voice: str
    engine: str  # "flite" | "espeak-ng"
    take: int
    duration_s: float  # exact: frames / sample rate
    near: str | None = None  # the trigger word a distractor resembles


class VoiceBank:
    """Clips listed in ``index.json`` with their samples loaded on demand and cached."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        index = json.loads((folder / "index.json").read_text(encoding="utf-8"))
        self.sample_rate = int(index["sample_rate"])
        self.clips: tuple[Clip, ...] = tuple(
            Clip(file=c["file"], text=c["text"], kind=c["kind"], voice=c["voice"],
                 engine=c["engine"], take=int(c["take"]),
                 duration_s=(int(c["frames"]) / self.sample_rate if "frames" in c
                             else float(c["duration_s"])),
                 near=c.get("near"))
            for c in index["clips"]
        )
        self._samples: dict[str, np.ndarray] = {}

    def trigger_words(self) -> list[str]:
        """The trigger words with at least one clip, sorted."""
        return sorted({c.text for c in self.clips if c.kind == "trigger"})

    def select(self, kind: str | None = None, text: str | None = None) -> list[Clip]:
        """Clips filtered by kind and/or exact text."""
        return [c for c in self.clips
                if (kind is None or c.kind == kind) and (text is None or c.text == text)]

    def samples(self, clip: Clip) -> np.ndarray:
        """The clip's samples, float64 mono at :attr:`sample_rate`."""
        data = self._samples.get(clip.file)
        if data is None:
            data, sr = sf.read(str(self.folder / clip.file), dtype="float64", always_2d=True)
            if sr != self.sample_rate:
                raise ValueError(f"{clip.file}: {sr} Hz, index says {self.sample_rate} Hz")
            data = data[:, 0].copy()
            self._samples[clip.file] = data
        return data


@lru_cache(maxsize=1)
def load_bank() -> VoiceBank:
    """The bundled clip bank (``resources/voices``), loaded once per process."""
    return VoiceBank(resource("voices"))


def available_trigger_words() -> list[str]:
    """The trigger words ``speechcal synth --trigger-word`` can speak."""
    return load_bank().trigger_words()


def check_trigger_word(word: str) -> str:
    """Return ``word`` normalized (lower case); UsageError naming the bundled words if absent."""
    normalized = word.strip().lower()
    words = available_trigger_words()
    if normalized not in words:
        raise UsageError(
            f"--trigger-word {word!r} has no bundled voice clips; use one of {', '.join(words)}"
        )
    return normalized
