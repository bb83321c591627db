"""What the drawing functions share about matplotlib's backend."""

from __future__ import annotations


def backend_is_interactive() -> bool:
    """False for the file-only backends (Agg, PDF, SVG, ...), where plt.show cannot show."""
    import matplotlib

    backend = matplotlib.get_backend().lower()
    try:
        from matplotlib.backends import BackendFilter, backend_registry

        non_interactive = backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE)
    except ImportError:  # matplotlib < 3.9
        from matplotlib.rcsetup import non_interactive_bk as non_interactive
    return backend not in {name.lower() for name in non_interactive}


def show_if_interactive(created: bool, block) -> None:
    """plt.show for a figure this call created, only where a window can appear."""
    if not (created and backend_is_interactive()):
        return
    import matplotlib.pyplot as plt

    if block is None:
        plt.show()
    else:
        plt.show(block=bool(block))
