"""numpy image -> QImage without copying more than once."""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QImage


def to_qimage(frame: np.ndarray) -> QImage:
    """Wrap a decoded frame (mono8/mono16 or BGR uint8) as a QImage that owns its data."""
    frame = np.ascontiguousarray(frame)
    h, w = frame.shape[:2]
    if frame.ndim == 2 and frame.dtype == np.uint16:
        image = QImage(frame.data, w, h, frame.strides[0], QImage.Format.Format_Grayscale16)
    elif frame.ndim == 2:
        frame = frame.astype(np.uint8, copy=False)
        image = QImage(frame.data, w, h, frame.strides[0], QImage.Format.Format_Grayscale8)
    else:
        frame = np.ascontiguousarray(frame[:, :, :3]).astype(np.uint8, copy=False)
        image = QImage(frame.data, w, h, frame.strides[0], QImage.Format.Format_BGR888)
    return image.copy()  # detach from the numpy buffer
