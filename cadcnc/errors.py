"""The error tree: every failure cadcnc reports derives from :class:`CadcncError`.

The CLI turns these into one-line messages and non-zero exit codes; the library never
uses ``assert`` for input validation.
"""

from __future__ import annotations


class CadcncError(Exception):
    """Root of every error cadcnc raises on purpose."""

    exit_code = 1


class InputError(CadcncError):
    """A parameter given by the user is invalid (names the parameter and its unit)."""

    exit_code = 2


class StepFileError(InputError):
    """A STEP file is missing, unreadable, or holds no solid or no faces."""


class FaceNumberError(InputError):
    """A face number is out of range 1..N for the part."""


class FacePairError(InputError):
    """Two faces cannot be machined as an intersection pair (not adjacent, convex, tangent)."""


class GeometryError(CadcncError):
    """The geometry forbids a computation (singular point, tangent faces, no convergence)."""

    exit_code = 3


class SingularPointError(GeometryError):
    """|r_u x r_w| vanishes at a parameter point (sphere pole, cone apex, degenerate edge)."""

    def __init__(self, message: str, u: float = float("nan"), w: float = float("nan")):
        super().__init__(message)
        self.u = u
        self.w = w


class StartPointError(GeometryError):
    """The initial tangency (cutter centre touching both offset surfaces) was not found."""


class OutputError(CadcncError):
    """An output file could not be written (unknown format, unwritable place)."""

    exit_code = 4


class ProgramSyntaxError(InputError):
    """A syntax error in an APT-like part program; names the line and column."""

    def __init__(self, message: str, line: int, column: int, source: str = "<program>"):
        super().__init__(f"{source}:{line}:{column}: {message}")
        self.line = line
        self.column = column
