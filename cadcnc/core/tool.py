"""The cutter: a ball-end tool, validated once where it is built. Lengths mm."""

from __future__ import annotations

from dataclasses import dataclass

from .units import check_number

SHANK_LENGTH_RADII = 10.0  # default shank length, in ball radii


@dataclass(frozen=True)
class Tool:
    """A ball-end cutter: ball radius R on a cylindrical shank of radius R along +Z.

    ``radius`` R and ``allowance`` C (stock left on the faces) in mm; the ball's offset from
    the faces is R' = R + C. ``shank_length`` (mm) above the ball centre, default 10 R.
    """

    radius: float
    allowance: float = 0.0
    shank_length: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "radius", check_number("radius", self.radius, "mm",
                                                        allow_zero=True))
        object.__setattr__(self, "allowance", check_number("allowance", self.allowance,
                                                           "mm", allow_zero=True))
        if self.shank_length is not None:
            object.__setattr__(self, "shank_length", check_number(
                "shank length", self.shank_length, "mm", allow_zero=True))

    @property
    def offset(self) -> float:
        """R' = R + C, mm: the ball centre's distance from a face it touches."""
        return self.radius + self.allowance

    @property
    def shank(self) -> float:
        """Shank length above the ball centre, mm (default 10 R)."""
        return SHANK_LENGTH_RADII * self.radius if self.shank_length is None \
            else self.shank_length
