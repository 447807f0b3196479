"""The output-path check every command runs before any work (SPEC §3).

A picture, page or scene file is written after the analysis; a path that cannot be written
would lose the result, and a path equal to an input would destroy it.  :func:`check_outputs`
looks at every output option a command has (:data:`OUTPUT_SUFFIXES`) and at every input file
it names (:data:`INPUT_OPTIONS`), so that a new command, or ``--html`` on a command that lacks it
today, is checked without a line of its own.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

#: Output options (argparse destination) and the suffixes each writes (lower case).
OUTPUT_SUFFIXES: dict[str, tuple[str, ...]] = {
    "plot": (".png", ".svg", ".pdf"),
    "html": (".html",),
    "export_scene": (".json", ".dxf"),
}
#: Options (argparse destination) that name an output folder (created when missing).
OUTPUT_FOLDERS: tuple[str, ...] = ("out",)
#: Options (argparse destination) that name an input file a command reads.
INPUT_OPTIONS: tuple[str, ...] = ("scene", "results", "courses", "design", "site")


class OutputPathError(ValueError):
    """An output path that cannot be written, or would overwrite an input (exit 2)."""


def check_output(path: str, option: str, suffixes: tuple[str, ...], inputs: list[Path]) -> None:
    """Refuse ``path`` (the value of ``--option``) unless it can be written as a new result.

    Raises
    ------
    OutputPathError
        Unknown suffix, a folder that is missing or not writable, a path that is a folder or a
        read-only file, or the path of an input file.
    """
    flag = "--" + option.replace("_", "-")
    target = Path(path)
    if target.suffix.lower() not in suffixes:
        raise OutputPathError(
            f"{flag} {path}: unknown file type {target.suffix or '(none)'!r}; "
            f"give a name ending in {', '.join(suffixes)}"
        )
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise OutputPathError(f"{flag} {path}: the folder '{folder}' does not exist")
    if target.is_dir():
        raise OutputPathError(f"{flag} {path}: is a folder, not a file")
    if not _can_create_in(folder):
        raise OutputPathError(f"{flag} {path}: the folder '{folder}' is not writable")
    if target.exists() and not _can_append(target):
        raise OutputPathError(f"{flag} {path}: the file exists and is not writable")
    for source in inputs:
        if _same_file(target, source):
            raise OutputPathError(f"{flag} {path}: is an input file of this command; it would be overwritten")


def check_outputs(args: argparse.Namespace) -> None:
    """Check every output path of ``args`` (:func:`check_output`) and that no two are the same."""
    inputs = [Path(str(getattr(args, name))) for name in INPUT_OPTIONS if getattr(args, name, None)]
    for option in OUTPUT_FOLDERS:
        folder = getattr(args, option, None)
        if folder and Path(folder).exists() and not Path(folder).is_dir():
            raise OutputPathError(f"--{option} {folder}: is a file, not a folder")
    written: list[Path] = []
    for option, suffixes in OUTPUT_SUFFIXES.items():
        path = getattr(args, option, None)
        if not path:
            continue
        check_output(path, option, suffixes, inputs)
        if any(_same_file(Path(path), other) for other in written):
            raise OutputPathError(
                f"--{option.replace('_', '-')} {path}: another output of this command is written to the same file"
            )
        written.append(Path(path))


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be created in ``folder``: tried, since permission bits do not tell
    (a superuser, a read-only mount, /proc); the probe file is removed at once."""
    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".alma-probe-"):
            return True
    except OSError:
        return False


def _can_append(path: Path) -> bool:
    """Whether the existing file ``path`` opens for writing (opened to append: nothing changes)."""
    try:
        with open(path, "ab"):
            return True
    except OSError:
        return False


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (symbolic links and relative paths resolved)."""
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
        return a.resolve() == b.resolve()
    except OSError:
        return False
