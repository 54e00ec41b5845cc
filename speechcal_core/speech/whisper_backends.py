"""Optional Whisper backends (faster-whisper, WhisperX): local model folders only, no download."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechError

if TYPE_CHECKING:
    from speechcal_core.audio import Audio
    from speechcal_core.speech.matching import TriggerSpec

RATE = 16000
#: backend name -> the Python package it needs
PACKAGES = {"faster-whisper": "faster_whisper", "whisperx": "whisperx"}


def require(backend: str, model_dir: str | Path | None) -> Path:
    """Check that the package is installed and the model folder exists; return the folder.

    Raises SpeechError with what to install or which folder to give. Nothing is downloaded.
    """
    package = PACKAGES[backend]
    if importlib.util.find_spec(package) is None:
        raise SpeechError(
            f"backend {backend!r} needs the Python package {package!r}, which is not "
            f"installed in the Python speechcal runs on; run `{sys.executable} -m pip "
            f"install {backend}` or use --backend pocketsphinx"
        )
    if not model_dir:
        raise SpeechError(
            f"backend {backend!r} needs a local model folder (nothing is downloaded); "
            f"give it with --model-dir, e.g. a CTranslate2 Whisper model folder"
        )
    p = Path(model_dir)
    if not p.is_dir():
        raise SpeechError(f"{p}: model folder not found; give the folder holding the "
                          f"{backend} model files with --model-dir")
    return p


class FasterWhisperBackend:
    """faster-whisper with ``word_timestamps=True`` on a local CTranslate2 model folder."""

    name = "faster-whisper"

    def __init__(self, model_dir: str | Path | None, device: str = "cpu") -> None:
        self.model_dir = require(self.name, model_dir)
        self.device = device

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        """Every word Whisper hears, with its timing and probability."""
        from faster_whisper import WhisperModel  # type: ignore[import-not-found]

        model = WhisperModel(str(self.model_dir), device=self.device, local_files_only=True)
        samples = audio.resampled(RATE).samples
        segments, _info = model.transcribe(samples, word_timestamps=True,
                                           hotwords=" ".join(spec.words))
        return [Word(w.word.strip(), float(w.start), float(w.end), float(w.probability),
                     self.name)
                for seg in segments for w in (seg.words or [])]


class WhisperXBackend:
    """WhisperX: Whisper transcription plus wav2vec2 alignment, from local model folders."""

    name = "whisperx"

    def __init__(self, model_dir: str | Path | None, device: str = "cpu") -> None:
        self.model_dir = require(self.name, model_dir)
        self.device = device

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        """Aligned words; words WhisperX could not align carry no time and are left out."""
        import whisperx  # type: ignore[import-not-found]

        samples = audio.resampled(RATE).samples
        model = whisperx.load_model(str(self.model_dir), self.device, compute_type="int8",
                                    local_files_only=True)
        result: Any = model.transcribe(samples)
        align_model, meta = whisperx.load_align_model(
            language_code=result.get("language", "en"), device=self.device,
            model_dir=str(self.model_dir))
        aligned = whisperx.align(result["segments"], align_model, meta, samples, self.device)
        out = []
        for w in aligned.get("word_segments", []):
            if "start" in w and "end" in w:
                out.append(Word(str(w["word"]).strip(), float(w["start"]), float(w["end"]),
                                float(w.get("score", 1.0)), self.name))
        return out
