"""A progress bar in simulated time: ``t`` of ``t_end`` with an ETA, one State at a time."""

from __future__ import annotations

__all__ = ["TimeBar", "time_bar"]

FORMAT = "{desc}: {percentage:3.0f}%|{bar}| t = {n:.4g}/{total:.4g} [{elapsed}<{remaining}{postfix}]"


class TimeBar:
    """A tqdm bar over ``[t_start, t_end]``, advanced by each State's ``t`` (fixed or adaptive
    steps alike); ``close()`` when the run ends."""

    def __init__(self, desc: str, t_end: float, t_start: float = 0.0):
        from tqdm import tqdm

        self.t = float(t_start)
        self.bar = tqdm(total=float(t_end), initial=self.t, desc=desc, bar_format=FORMAT, leave=True)

    def __call__(self, state) -> None:
        t = float(state.t)
        if t > self.t:
            self.bar.update(t - self.t)
            self.t = t
        self.bar.set_postfix(
            step=state.step, load=f"{state.load:.4g}", dmin=f"{state.film_min:.3g}", refresh=False
        )

    def close(self) -> None:
        self.bar.close()


def time_bar(desc: str, t_end: float, t_start: float = 0.0) -> TimeBar:
    """A :class:`TimeBar` named ``femehl <desc>`` (the ``progress`` of :func:`femehl.solve`)."""
    return TimeBar(f"femehl {desc}", t_end, t_start)
