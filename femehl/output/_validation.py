"""Validators of run and command-line options, applied before anything is written.

Small functions: each returns the checked value (never mutating its input) or
raises :class:`~femehl.errors.SceneError` with a message that names the fix.
"""

from __future__ import annotations

import numbers

from femehl.errors import SceneError

__all__ = [
    "METHOD_FLAGS",
    "check_count",
    "check_divisions",
    "check_flag",
    "check_method_flags",
    "check_resume_overwrite",
    "check_run_options",
    "check_step",
]


def check_count(name: str, value, minimum: int = 0, hint: str = "") -> int:
    """``value`` as an int >= ``minimum``; booleans, floats and strings are refused."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise SceneError(
            f"{name} must be an integer >= {minimum}, got {value!r} ({type(value).__name__}). {hint}".strip()
        )
    if value < minimum:
        raise SceneError(f"{name} must be an integer >= {minimum}, got {value}. {hint}".strip())
    return int(value)


def check_flag(name: str, value) -> bool:
    """``value`` as a bool; only True and False are accepted."""
    if not isinstance(value, bool):
        raise SceneError(f"{name} must be True or False, got {value!r}.")
    return value


def check_resume_overwrite(resume, overwrite) -> tuple[bool, bool]:
    """Both flags as bools; asking for both at once is refused."""
    resume, overwrite = check_flag("resume", resume), check_flag("overwrite", overwrite)
    if resume and overwrite:
        raise SceneError(
            "resume and overwrite exclude each other: --resume continues the run in the "
            "folder, --overwrite replaces it; give one of them."
        )
    return resume, overwrite


def check_tol(tol, name: str = "tol"):
    """``tol`` (or ``step_tol``) as a float in (0, 0.5), or None."""
    if tol is None:
        return None
    from femehl.validation import check_positive

    tol = check_positive(name, tol, f"Give a relative error, e.g. {name} = 1e-2.")
    if tol >= 0.5:
        raise SceneError(f"{name} = {tol:g} is not a relative error: give 0 < {name} < 0.5, e.g. 1e-2.")
    return tol


def check_run_options(t_end, dt, store_every, checkpoint_every):
    """``(t_end, dt, nsteps, store_every, checkpoint_every)`` of a run, checked.

    ``checkpoint_every`` None means ``store_every``; 0 means only at the end.
    """
    from femehl.solver.stepping import check_run

    t_end, dt, nsteps = check_run(t_end, dt)
    store_every = check_count(
        "store_every", store_every, 0, "Give how many steps apart fields are written (0: only at the end)."
    )
    if checkpoint_every is None:
        checkpoint_every = store_every
    checkpoint_every = check_count(
        "checkpoint_every",
        checkpoint_every,
        0,
        "Give how many steps apart the checkpoint is saved (0: only at the end).",
    )
    return t_end, dt, nsteps, store_every, checkpoint_every


def check_divisions(value) -> int:
    """``--dtheta-divisions N`` (dtheta = pi/N): an integer >= 2."""
    return check_count("--dtheta-divisions", value, 2, "dtheta = pi/N: give N >= 2 (the paper uses 36).")


def check_step(name: str, value) -> float:
    """A finite grid step > 0 (``--dr``)."""
    from femehl.problem.scene import check_positive

    return check_positive(name, value, "Give a positive grid step (FD default 0.0125).")


#: command-line flags that only one method understands (argparse dest -> flag, methods)
METHOD_FLAGS = {
    "mesh": ("--mesh", ("fe",)),
    "scheme": ("--scheme", ("fe", "line")),
    "dr": ("--dr", ("fd",)),
    "dtheta_divisions": ("--dtheta-divisions", ("fd",)),
    "n_elements": ("--n-elements", ("line",)),
}


#: what to say instead of "use another method" where the scene fixes the method
METHOD_HINTS = {"line": " (line contact is a 1-D mesh of [-L, L]: give --n-elements instead)"}


def check_method_flags(method: str, given: dict) -> None:
    """Refuse command-line flags that ``method`` does not use.

    ``given`` maps argparse names to the values given (None: not given).  ``--scheme euler``
    is accepted with fd: it is the scheme the FD reference uses.
    """
    bad = []
    for key, value in given.items():
        if value is None or key not in METHOD_FLAGS:
            continue
        flag, methods = METHOD_FLAGS[key]
        if method in methods or (key == "scheme" and method == "fd" and value == "euler"):
            continue
        bad.append(flag)
    if bad:
        users = sorted(
            {
                m
                for key, value in given.items()
                if value is not None and key in METHOD_FLAGS
                for m in METHOD_FLAGS[key][1]
            }
            - {method}
        )
        hint = METHOD_HINTS.get(method) or (f" or use --method {' / '.join(users)}" if users else "")
        raise SceneError(
            f"{', '.join(bad)} do(es) not apply to --method {method}: drop "
            f"{'them' if len(bad) > 1 else 'it'}{hint}."
        )
