"""``ltl-human-motion render MOTION.npz --out FILE.gif|png``: look at a synthesized motion.

A ``.gif`` is the animation of the whole motion; a ``.png`` (or ``.svg``/``.pdf``) a sheet
of snapshots: the start and the middle of each task, titled with the time and the task.
The worker is drawn in the cell the motion was made in (named in the motion's name, as
``synthesize`` writes it) or in ``--cell``.
"""

from __future__ import annotations

import argparse
import re
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path

from ltl_human_motion.errors import CellError, MotionFormatError

NAME = "render"
HELP = "draw a synthesized motion (npz or json) as a GIF animation or a PNG sheet of snapshots"

GIF_SUFFIXES = (".gif",)
SHEET_SUFFIXES = (".png", ".svg", ".pdf")
#: Pixels per inch of the two kinds of picture (their sizes are given in pixels).
GIF_DPI = 80.0
SHEET_DPI = 110.0
#: Default pixel sizes: a GIF frame, one panel of the sheet.
GIF_SIZE = (800, 600)
PANEL_SIZE = (440, 396)
MIN_PIXELS, MAX_PIXELS = 64, 4096
_NAME_PATTERN = re.compile(r"^(?P<cell>[A-Za-z0-9_.-]+?)-seed-?\d+-v\d+$")


@dataclass(frozen=True)
class PictureOptions:
    """How pictures are drawn: sizes in pixels (width, height), GIF frame rate in Hz."""

    gif_size: tuple[int, int] = GIF_SIZE
    panel_size: tuple[int, int] = PANEL_SIZE
    fps: float = 10.0
    max_panels: int = 9
    body: str = "shaded"


def pixel_size(text: str) -> tuple[int, int]:
    """argparse type of ``--size``: ``WxH`` in pixels, each 64-4096."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", text)
    if not m:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels such as 800x600, "
                                         f"got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    if not (MIN_PIXELS <= w <= MAX_PIXELS and MIN_PIXELS <= h <= MAX_PIXELS):
        raise argparse.ArgumentTypeError(f"width and height must be {MIN_PIXELS}-{MAX_PIXELS} "
                                         f"pixels, got {w}x{h}")
    return w, h


def add_picture_arguments(parser: argparse.ArgumentParser, what: str) -> None:
    """``--size``, ``--fps`` and ``--body``, shared by ``render`` and ``synthesize``."""
    parser.add_argument("--size", type=pixel_size, default=None, metavar="WxH",
                        help=f"picture size in pixels of the GIF frame and of each snapshot "
                             f"panel of the PNG (default {GIF_SIZE[0]}x{GIF_SIZE[1]} and "
                             f"{PANEL_SIZE[0]}x{PANEL_SIZE[1]}){what}")
    parser.add_argument("--fps", type=float, default=10.0,
                        help="frame rate of the GIF in Hz (default 10)")
    parser.add_argument("--body", choices=("shaded", "stick"), default="shaded",
                        help="draw the worker as a shaded body (default) or a stick figure")


def picture_options(args: argparse.Namespace) -> PictureOptions | str:
    """The picture options of parsed arguments (see :func:`add_picture_arguments`), or
    what is wrong with them."""
    if not 0 < args.fps <= 120:
        return f"--fps must be in (0, 120] Hz, got {args.fps:g}"
    size = args.size
    return PictureOptions(gif_size=size or GIF_SIZE, panel_size=size or PANEL_SIZE,
                          fps=args.fps, body=args.body)


def write_gif(synth, cell, path: Path, options: PictureOptions) -> int:
    """The animation of ``synth`` in ``cell``; returns the number of frames."""
    from ltl_human_motion.viz import render_animation
    w, h = options.gif_size
    return render_animation(synth, cell, path, fps=options.fps, size=(w / GIF_DPI, h / GIF_DPI),
                            dpi=GIF_DPI, body=options.body)


def write_sheet(synth, cell, path: Path, options: PictureOptions) -> int:
    """A sheet of snapshots (start, middle of each task); returns the number of panels."""
    from ltl_human_motion.viz import render_snapshots, task_snapshot_times
    times = task_snapshot_times(synth, options.max_panels)
    w, h = options.panel_size
    title = f"{synth.spec or synth.motion.name}:  {' ; '.join(synth.sequence)}"
    render_snapshots(synth, cell, times, path, ncols=min(3, len(times)), dpi=SHEET_DPI,
                     panel_size=(w / SHEET_DPI, h / SHEET_DPI), body=options.body,
                     title=title if len(title) < 160 else title[:157] + "...")
    return len(times)


def cell_of(synth, cell: str | None):
    """The cell to draw ``synth`` in: ``cell`` if given, else the one its name names."""
    from ltl_human_motion.scene.cell_yaml import cell_by_name, resolve_cell
    if cell:
        return resolve_cell(cell)
    m = _NAME_PATTERN.match(synth.motion.name or "")
    if not m:
        raise CellError(f"the motion (name {synth.motion.name!r}) does not say which cell it "
                        "was made in; pass --cell NAME_OR_PATH")
    try:
        return cell_by_name(m.group("cell"))
    except CellError as exc:
        raise CellError(f"the motion was made in cell {m.group('cell')!r} (from its name), "
                        f"which is not a shipped cell ({exc}); pass --cell PATH") from None


def load_motion(path: Path):
    """A motion written by ``synthesize --out`` (``.npz`` or ``.json``)."""
    from ltl_human_motion.planning import exports
    if not path.exists():
        raise MotionFormatError(f"{path}: no such file")
    if path.is_dir():
        raise MotionFormatError(f"{path}: is a folder; give one motion file such as "
                                f"{path / 'motion_000.npz'}")
    if path.suffix.lower() == ".json":
        return exports.load_json(path)
    if path.suffix.lower() != ".npz":
        raise MotionFormatError(f"{path}: expected a .npz or .json motion written by "
                                "ltl-human-motion synthesize --out")
    if not zipfile.is_zipfile(path):
        raise MotionFormatError(f"{path}: not an npz archive (a zip file), so not a motion "
                                "written by ltl-human-motion synthesize --out")
    return exports.load_npz(path)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion render``."""
    parser.add_argument("motion", type=Path,
                        help="motion file written by synthesize into its --out folder "
                             "(motion_000.npz or .json)")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE",
                        help="output picture: .gif (animation) or .png, .svg, .pdf (sheet of "
                             "snapshots)")
    parser.add_argument("--cell", default=None,
                        help="cell to draw the motion in (default: the cell named in the "
                             "motion, e.g. paper_cell)")
    add_picture_arguments(parser, "")


def run(args: argparse.Namespace) -> int:
    """Draw the motion into ``--out``; print what was written."""
    suffix = args.out.suffix.lower()
    options = picture_options(args)
    if suffix not in GIF_SUFFIXES + SHEET_SUFFIXES:
        options = (f"--out {args.out}: the file must end in "
                   f"{', '.join(GIF_SUFFIXES + SHEET_SUFFIXES)}")
    if isinstance(options, str):
        print(f"ltl-human-motion {NAME}: error: {options}", file=sys.stderr)
        return 2
    synth = load_motion(args.motion)
    cell = cell_of(synth, args.cell)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    if suffix in GIF_SUFFIXES:
        n = write_gif(synth, cell, args.out, options)
        what = f"{n} frames at {options.fps:g} Hz, {options.gif_size[0]}x{options.gif_size[1]}"
    else:
        n = write_sheet(synth, cell, args.out, options)
        what = f"{n} snapshots"
    print(f"wrote {args.out} ({what}; {synth.duration:.1f} s of motion in {cell.name})")
    return 0
