"""The output folder of a run: is it usable, does it hold a run, clearing femehl's own files.

:func:`check_folder` only looks (nothing is created or removed), so a run can
refuse a folder before it touches anything; :func:`prepare_folder` then creates
it and, when asked to overwrite, removes femehl's files of the old run (and only
those: a user's own files in the folder are never deleted).
"""

from __future__ import annotations

import os
import pathlib
import re

from femehl.errors import CheckpointError, OutputError

__all__ = ["RUN_FILES", "check_folder", "clear_run_files", "prepare_folder", "run_files"]

#: the files a femehl run writes into its folder (besides the field series fields_NNNNNN.vtu)
RUN_FILES = (
    "summary.csv",
    "summary_si.csv",
    "fields.pvd",
    "checkpoint.npz",
    "checkpoint.json",
    "centreline.png",
    "fields.png",
    "maps.png",
    "history.png",
    "animation.gif",
    "line.png",
    "auto.json",
    "summary_estimate_before_resume.csv",
)
_SERIES = re.compile(r"fields_\d+\.vtu$")
_MAPS = re.compile(r"maps_t[-+.\w]+\.png$")  # femehl plot maps RUN --t T
_TEMPORARY = re.compile(r"(fields\.pvd|checkpoint\.npz|checkpoint\.json|fields_\d+\.vtu)\.tmp$")

_FIX = (
    "give overwrite=True (--overwrite) to replace it, resume=True (--resume) to continue it, "
    "or another folder (--out)"
)


def _is_run_file(name: str) -> bool:
    return name in RUN_FILES or bool(_SERIES.match(name)) or bool(_MAPS.match(name))


def run_files(folder, temporary: bool = False) -> list[pathlib.Path]:
    """femehl's files of a run present in ``folder`` (with ``temporary``: also its .tmp leftovers)."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        return []
    return sorted(
        p for p in folder.iterdir() if _is_run_file(p.name) or (temporary and _TEMPORARY.match(p.name))
    )


def _writable(path: pathlib.Path) -> bool:
    return os.access(path, os.W_OK | os.X_OK)


def _check_path(folder: pathlib.Path) -> None:
    """The folder is, or can be made, a writable directory."""
    for p in (folder, *folder.parents):
        if p.is_dir():
            break
        if p.exists() or p.is_symlink():
            if p == folder:
                raise OutputError(
                    f"the output folder {str(folder)!r} is a file, not a folder: "
                    "give another folder (--out), or move the file away."
                )
            raise OutputError(
                f"the output folder {str(folder)!r} cannot be made: {str(p)!r} is a "
                "file, not a folder; give another folder (--out)."
            )
    else:  # pragma: no cover - "/" always exists
        p = folder
    if not _writable(p):
        if p == folder:
            raise OutputError(
                f"the output folder {str(folder)!r} is not writable: give another "
                "folder (--out) or change its permissions."
            )
        raise OutputError(
            f"the output folder {str(folder)!r} cannot be made: {str(p)!r} is not "
            "writable; give another folder (--out) or change its permissions."
        )


def check_folder(folder, *, resume: bool = False, overwrite: bool = False) -> pathlib.Path:
    """Check that a run may write into ``folder`` as asked; touch nothing.

    Refused with :class:`~femehl.errors.OutputError`: a path that is a file or under
    one, a folder that is not writable, a femehl file name taken by a directory, and
    a folder that already holds a run unless ``overwrite`` or ``resume``.  ``resume``
    needs the run's checkpoint (:class:`~femehl.errors.CheckpointError`).
    """
    folder = pathlib.Path(folder)
    _check_path(folder)
    if not folder.is_dir():
        if resume:
            raise CheckpointError(
                f"cannot resume: the output folder {str(folder)!r} does not exist; "
                "give the folder of the run to continue, or run without resume."
            )
        return folder
    for name in RUN_FILES:
        p = folder / name
        if p.exists() and not p.is_file():
            raise OutputError(
                f"{str(p)!r} is not a regular file (a directory?), but femehl writes its "
                f"{name} there: move it away or give another folder (--out)."
            )
    present = run_files(folder)
    if present and not (resume or overwrite):
        names = ", ".join(p.name for p in present[:4]) + (", ..." if len(present) > 4 else "")
        raise OutputError(f"the output folder {str(folder)!r} already holds a run ({names}): {_FIX}.")
    if resume and not (folder / "checkpoint.npz").is_file():
        raise CheckpointError(
            f"cannot resume: no checkpoint in {str(folder)!r} (checkpoint.npz is "
            "missing); give the folder of the run to continue, or start it again "
            "with overwrite=True (--overwrite)."
        )
    return folder


def clear_run_files(folder) -> list[pathlib.Path]:
    """Remove femehl's files of a run (and its .tmp leftovers) from ``folder``; nothing else."""
    removed = []
    for p in run_files(folder, temporary=True):
        if p.is_file() or p.is_symlink():
            p.unlink()
            removed.append(p)
    return removed


def prepare_folder(folder, *, overwrite: bool = False) -> list[pathlib.Path]:
    """Create ``folder``; with ``overwrite`` remove the old run's files.  Returns those removed.

    Call :func:`check_folder` first: this one writes.
    """
    folder = pathlib.Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return clear_run_files(folder) if overwrite else []
    except OSError as exc:
        raise OutputError(
            f"cannot prepare the output folder {str(folder)!r} ({exc.strerror or exc}): "
            "give another folder (--out) or fix its permissions."
        ) from None
