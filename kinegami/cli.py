"""The ``kinegami`` command line (a thin shell over the library)."""

from __future__ import annotations

import argparse

from kinegami import __version__


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``kinegami`` console script."""
    parser = argparse.ArgumentParser(
        prog="kinegami",
        description="Design tubular origami kinematic chains and their crease patterns.",
    )
    parser.add_argument("--version", action="version", version=f"kinegami {__version__}")
    parser.parse_args(argv)
    parser.print_help()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
