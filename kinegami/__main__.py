"""``python -m kinegami``: the ``kinegami`` command, run from the package that Python imports
(the source tree when it is on the path; tests/cli/helpers.py runs the command this way)."""

from kinegami.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
