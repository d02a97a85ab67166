"""Record files the tests write (CSV in g), shared by the vertical-shaking tests."""

from __future__ import annotations

import numpy as np

from rbm_cli.config.types import G
from rbm_cli.inputs.records import write_csv


def half_sine_csv(path, f):
    """A 1 g half-sine of frequency f [Hz] as a CSV, 2000 samples; its path."""
    end = 0.5 / f
    t = np.linspace(0.0, end, 2001)
    a = G * np.sin(np.pi * t / end)
    a[0] = a[-1] = 0.0
    return write_csv(path, (t, a), units="g")
