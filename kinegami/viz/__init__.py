"""Plotting backends (matplotlib); the model imports them lazily from ``show()``."""
