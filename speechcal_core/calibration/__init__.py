"""Quick per-camera calibration check from the frame sets' target corners."""
