"""Shared pytest set-up: draw with the non-interactive Agg backend."""

import matplotlib

matplotlib.use("Agg")
