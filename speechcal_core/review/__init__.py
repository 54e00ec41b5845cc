"""Headless review state: what the window shows and every action it offers."""
