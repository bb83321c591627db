"""The ``kinegami`` command line: a thin shell over the library.

Commands::

    kinegami build DESIGN -o DIR [--formats dxf,svg,png] [--name STEM]
    kinegami show DESIGN [--pattern]
    kinegami validate DESIGN

Exit codes: 0 success, 1 a design or export error (one line on stderr, no traceback, no file
written), 2 a usage error (argparse).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from kinegami import __version__
from kinegami.errors import KinegamiError

#: Millimetres per design length unit.
UNITS_IN_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}


class CommandError(Exception):
    """A failure reported as one line on stderr with exit code 1."""


# --- outputs of `build` ------------------------------------------------------------------------
@dataclass(frozen=True)
class OutputFormat:
    """One ``--formats`` entry: the files it writes and how."""

    name: str
    description: str
    suffixes: tuple[str, ...]  # file name endings after the stem, e.g. ("_3d.png", ...)
    write: Callable[..., None]  # write(job, paths) with one path per suffix


@dataclass
class BuildJob:
    """What the writers need: the chain, its pattern and the design's metadata."""

    chain: object
    info: object
    _pattern: object = None

    @property
    def pattern(self):
        if self._pattern is None:
            self._pattern = self.chain.creasePattern(twistPortion=self.info.twistPortion)
        return self._pattern


def _write_pattern_file(job: BuildJob, paths: list[Path]) -> None:
    from kinegami.export import save_pattern

    save_pattern(job.pattern, paths[0], units=job.info.units)


def _write_pngs(job: BuildJob, paths: list[Path]) -> None:
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    fig, _ = job.chain.show(block=False)
    try:
        fig.savefig(paths[0], dpi=150, bbox_inches="tight")
    finally:
        plt.close(fig)
    fig, _ = job.pattern.show()
    try:
        fig.savefig(paths[1], dpi=150, bbox_inches="tight")
    finally:
        plt.close(fig)


def _registry_writer(suffix: str) -> Callable[..., None]:
    """A writer through :func:`kinegami.export.export`: pattern formats get the design's
    pattern, chain formats the chain (with the design's twistPortion and units)."""

    def write(job: BuildJob, paths: list[Path]) -> None:
        from kinegami.export.registry import FORMATS, export

        if FORMATS[suffix].accepts == "pattern":
            export(job.pattern, paths[0], units=job.info.units)
        else:
            export(job.chain, paths[0], units=job.info.units, twistPortion=job.info.twistPortion)

    return write


def output_formats() -> dict[str, OutputFormat]:
    """The formats ``build --formats`` accepts, by name."""
    formats = {
        "dxf": OutputFormat("dxf", "crease pattern for a laser cutter", (".dxf",),
                            _write_pattern_file),
        "svg": OutputFormat("svg", "crease pattern (Origami Simulator, browsers)", (".svg",),
                            _write_pattern_file),
        "png": OutputFormat("png", "pictures of the 3D chain and of the pattern",
                            ("_3d.png", "_pattern.png"), _write_pngs),
    }  # fmt: skip
    try:
        from kinegami.export.registry import known_formats
    except ImportError:  # pragma: no cover - exporters of issue 5 not installed
        return formats
    for suffix, description in known_formats().items():
        name = suffix.lstrip(".")
        if name not in formats:
            formats[name] = OutputFormat(name, description, (suffix,), _registry_writer(suffix))
    return formats


DEFAULT_FORMATS = ("dxf", "svg", "png")


def _parse_formats(text: str) -> list[OutputFormat]:
    known = output_formats()
    names = [item.strip().lower().lstrip(".") for item in text.split(",") if item.strip()]
    if not names:
        raise CommandError(f"--formats: no format given; known: {', '.join(known)}")
    if "all" in names:
        return list(known.values())
    unknown = [name for name in names if name not in known]
    if unknown:
        raise CommandError(
            f"--formats: unknown format {unknown[0]!r}; known: {', '.join(known)}, all"
        )
    return [known[name] for name in dict.fromkeys(names)]


# --- helpers -----------------------------------------------------------------------------------
def _load(design: str):
    from kinegami.design import load_design_with_info

    return load_design_with_info(design)


def _existing_ancestor(path: Path) -> Path:
    path = path.absolute()
    while not path.exists():
        path = path.parent
    return path


def _summary(chain, info, design: str) -> list[str]:
    from collections import Counter

    from kinegami.pattern.sheet import flatten

    factor = UNITS_IN_MM[info.units]
    counts = Counter(type(joint).__name__ for joint in chain.Joints)
    kinds = ", ".join(f"{count} {name}" for name, count in counts.items())
    sheet = flatten(chain.creasePattern(twistPortion=info.twistPortion))
    xmin, ymin, xmax, ymax = sheet.bounds
    links = len(chain.Joints) - 1
    joints_length = sum(joint.neutralLength for joint in chain.Joints)
    links_length = chain.totalPathLength()
    tube = links_length + joints_length
    title = f"{info.name} ({design})" if info.name else design
    return [
        title,
        f"  joints: {len(chain.Joints)} ({kinds})",
        f"  links: {links}",
        f"  tube: {chain.numSides} sides, r = {chain.r * factor:g} mm",
        f"  sheet: {(xmax - xmin) * factor:.1f} mm x {(ymax - ymin) * factor:.1f} mm",
        f"  total tube length: {tube * factor:.1f} mm "
        f"(links {links_length * factor:.1f} mm, joints {joints_length * factor:.1f} mm)",
    ]


# --- commands ----------------------------------------------------------------------------------
def cmd_build(args: argparse.Namespace) -> int:
    formats = _parse_formats(args.formats)
    chain, info = _load(args.design)
    stem = args.name or Path(args.design).stem
    if not stem or os.sep in stem or (os.altsep and os.altsep in stem):
        raise CommandError(f"--name: {stem!r} is not a plain file name")
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise CommandError(f"-o: {str(out)!r} exists and is not a folder")
    job = BuildJob(chain, info)
    lines = _summary(chain, info, args.design)
    # write everything into a hidden staging folder, then move the files in: a failure
    # leaves nothing behind
    try:
        staging = Path(tempfile.mkdtemp(prefix=".kinegami-build-", dir=_existing_ancestor(out)))
    except OSError as error:
        raise CommandError(f"-o: cannot write in {str(out)!r}: {error.strerror}") from None
    written: list[Path] = []
    try:
        for fmt in formats:
            fmt.write(job, [staging / f"{stem}{suffix}" for suffix in fmt.suffixes])
        # exporters may write more than their file (a URDF's mesh folder): move everything
        staged = sorted(staging.iterdir())
        out.mkdir(parents=True, exist_ok=True)
        for path in staged:
            target = out / path.name
            if path.is_dir() and target.is_dir():
                shutil.rmtree(target)  # a folder this build owns, e.g. <stem>_meshes/
            os.replace(path, target)
            written.append(target)
    except OSError as error:
        for path in written:
            if path.is_dir():
                shutil.rmtree(path, ignore_errors=True)
            else:
                path.unlink(missing_ok=True)
        raise CommandError(f"cannot write to {str(out)!r}: {error.strerror or error}") from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    lines.append("  files written:")
    lines.extend(f"    {path}{os.sep if path.is_dir() else ''}" for path in written)
    print("\n".join(lines))
    return 0


def cmd_show(args: argparse.Namespace) -> int:
    import matplotlib.pyplot as plt

    from kinegami.viz._backend import backend_is_interactive

    chain, info = _load(args.design)
    if not backend_is_interactive():
        raise CommandError(
            "cannot open a window: matplotlib has no interactive backend here (no display?); "
            "use 'kinegami build DESIGN -o DIR' to write pictures instead"
        )
    chain.show(block=False)
    if args.pattern:
        chain.creasePattern(twistPortion=info.twistPortion).show()
    plt.show()
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    from kinegami.design import read_design, validate_design

    validate_design(args.design)
    data = read_design(args.design)
    if args.build:
        chain, _ = _load(args.design)
        print(f"{args.design}: valid; builds {len(chain.Joints)} joints")
        return 0
    if "joints" in data:
        what = f"{len(data['joints'])} joints"
    else:
        what = f"a DH table of {len(data['dh']['rows'])} rows"
    print(f"{args.design}: valid ({what}; placement not checked, use --build)")
    return 0


# --- parser ------------------------------------------------------------------------------------
def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="kinegami",
        description="Design tubular origami kinematic chains and their crease patterns.",
        epilog="Design files: see docs/design-format.md. "
        "Example: kinegami build examples/designs/example1.json -o out/",
    )
    parser.add_argument("--version", action="version", version=f"kinegami {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    build = commands.add_parser(
        "build",
        help="build a design: crease pattern files, pictures and a summary",
        description="Build the chain of a design file and write its crease pattern (DXF, SVG) "
        "and pictures (PNG of the 3D chain and of the pattern) to a folder; print a summary. "
        "Nothing is written if the design is invalid or infeasible.",
    )
    build.add_argument("design", metavar="DESIGN", help="design file (.json)")
    build.add_argument(
        "-o", "--output", metavar="DIR", required=True, help="output folder (created if missing)"
    )
    known = output_formats()
    build.add_argument(
        "--formats",
        default=",".join(DEFAULT_FORMATS),
        metavar="LIST",
        help="comma-separated outputs (default: %(default)s; 'all' for every one): "
        + "; ".join(f"{name} = {fmt.description}" for name, fmt in known.items()),
    )
    build.add_argument(
        "--name", metavar="STEM", help="file name stem of the outputs (default: the design's name)"
    )
    build.set_defaults(run=cmd_build)

    show = commands.add_parser(
        "show",
        help="open the 3D view of a design",
        description="Build a design and open its 3D view in a matplotlib window.",
    )
    show.add_argument("design", metavar="DESIGN", help="design file (.json)")
    show.add_argument("--pattern", action="store_true", help="also show the crease pattern")
    show.set_defaults(run=cmd_show)

    validate = commands.add_parser(
        "validate",
        help="check a design file without building it",
        description="Check a design file against the format (schema, types, ranges, rigid "
        "poses) without building the chain. With --build, also place every joint and apply "
        "the edits.",
    )
    validate.add_argument("design", metavar="DESIGN", help="design file (.json)")
    validate.add_argument(
        "--build", action="store_true", help="also build the chain (every placement and edit)"
    )
    validate.set_defaults(run=cmd_validate)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``kinegami`` console script; returns the exit code."""
    parser = make_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    try:
        return args.run(args)
    except (CommandError, KinegamiError) as error:
        print(f"kinegami {args.command}: error: {error}", file=sys.stderr)
        return 1
    except OSError as error:  # e.g. the design file cannot be read
        where = f": {error.filename!r}" if error.filename else ""
        print(f"kinegami {args.command}: error: {error.strerror or error}{where}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
