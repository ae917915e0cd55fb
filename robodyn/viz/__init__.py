"""Viewing: meshcat scenes, self-contained HTML recordings, stills from headless Chromium, the live viewer and matplotlib figures."""
