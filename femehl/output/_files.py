"""Where a picture or table goes, and writing it so a fault is femehl's error, not a traceback.

* :func:`out_path`: the file ``--out`` names (an existing folder, or a path ending in a
  separator, gets the usual file name inside it; a file name without suffix gets the
  usual suffix; a suffix the writer cannot write is refused);
* :func:`writing`: turns an ``OSError`` while writing into an
  :class:`~femehl.errors.OutputError` naming the folder and the fix;
* :func:`write_atomic`: writes through a temporary file and a rename, so a failed
  write (a full disk) leaves the file that was there before untouched.
"""

from __future__ import annotations

import contextlib
import errno
import os
import pathlib

from femehl.errors import OutputError

__all__ = ["out_path", "write_atomic", "writing"]


def _fix(exc: OSError) -> str:
    if exc.errno == errno.ENOSPC or exc.errno == errno.EDQUOT:
        return "free some space on that disk, or give --out on another disk"
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return "make the folder writable, or give --out in a folder you can write"
    if exc.errno in (errno.ENOENT, errno.ENOTDIR):
        return "give --out in an existing folder"
    return "check the folder, or give --out elsewhere"


@contextlib.contextmanager
def writing(path, what: str = "write"):
    """``OSError`` inside the block -> :class:`OutputError` naming ``path``'s folder and the fix."""
    path = pathlib.Path(path)
    try:
        yield path
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise OutputError(f"cannot {what} {path} in {path.parent} ({reason}): {_fix(exc)}.") from None


def write_atomic(path, write, what: str = "write") -> pathlib.Path:
    """``write(tmp)`` then rename ``tmp`` to ``path``; a failure leaves ``path`` as it was.

    ``tmp`` keeps ``path``'s suffix (``name.tmp.png``) so writers that pick the format by
    suffix write the right one.
    """
    path = pathlib.Path(path)
    tmp = path.with_name(f"{path.stem}.tmp{os.getpid()}{path.suffix}")
    with writing(path, what):
        try:
            write(tmp)
            os.replace(tmp, path)
        finally:
            with contextlib.suppress(OSError):
                tmp.unlink()
    return path


def out_path(out, folder, default_name: str, suffixes=None) -> pathlib.Path:
    """The file to write for ``--out out`` (None: ``folder/default_name``).

    ``out`` an existing folder, or ending in a path separator (the folder is created):
    ``out/default_name``.  Otherwise ``out`` is the file; without a suffix it gets
    ``default_name``'s.  ``suffixes`` (lower case, with the dot): the ones the writer
    can write; another is refused.  The file's folder must exist (or is created for a
    separator-ended ``out``).
    """
    default = pathlib.Path(default_name)
    if out is None:
        return pathlib.Path(folder) / default
    text = os.fspath(out)
    if not isinstance(text, str) or not text.strip():
        raise OutputError(f"--out must be a file or folder name, got {out!r}.")
    seps = (os.sep,) + ((os.altsep,) if os.altsep else ())
    path = pathlib.Path(text)
    if text.endswith(seps) or path.is_dir():
        with writing(path, "create the folder"):
            path.mkdir(parents=True, exist_ok=True)
        return path / default
    if not path.suffix:
        path = path.with_name(path.name + default.suffix)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise OutputError(
            f"--out {text}: cannot write a {path.suffix!r} file here; give a name ending in "
            f"{' or '.join(sorted(suffixes))}, or a folder (the picture is then {default.name} in it)."
        )
    if not path.parent.is_dir():
        raise OutputError(
            f"--out {text}: the folder {path.parent} does not exist: create it, or give --out in an "
            "existing folder (a name ending in / is a folder, created if needed)."
        )
    return path
