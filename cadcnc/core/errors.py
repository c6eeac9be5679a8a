"""The error tree: every failure cadcnc reports derives from :class:`CadcncError`.

The CLI turns these into one-line messages and non-zero exit codes; the library never
uses ``assert`` for input validation.
"""

from __future__ import annotations

# Exit codes, the one definition (docs/reliability.md): every command returns one of these.
EXIT_OK = 0              # a complete program that passed the gouge gate, written
EXIT_INTERNAL = 1        # an internal error (a bug: please report it)
EXIT_INPUT = 2           # bad command line or input (file, face, parameter)
EXIT_NOTHING = 3         # no program from valid input: nothing to cut or reach, no start
EXIT_OUTPUT = 4          # an output cannot be written
EXIT_GOUGE = 5           # the gate found a gouge: nothing written unless allowed
EXIT_PARTIAL = 6         # the program stops short of what was asked
EXIT_INTERRUPTED = 130   # interrupted (Ctrl-C)


class CadcncError(Exception):
    """Root of every error cadcnc raises on purpose."""

    exit_code = EXIT_INTERNAL


class InputError(CadcncError):
    """A parameter given by the user is invalid (names the parameter and its unit)."""

    exit_code = EXIT_INPUT


class OutputIsInputError(InputError):
    """An output of a run would be written over one of its inputs (both named): exit 2."""


class StepFileError(InputError):
    """A STEP file is missing, unreadable, or holds no solid or no faces."""


class FaceNumberError(InputError):
    """A face number is out of range 1..N for the part."""


class FacePairError(InputError):
    """Two faces cannot be machined as an intersection pair (not adjacent, convex, tangent)."""


class GeometryError(CadcncError):
    """The geometry forbids a computation (singular point, tangent faces, no convergence)."""

    exit_code = EXIT_NOTHING


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

    exit_code = EXIT_OUTPUT


class NothingToCutError(CadcncError):
    """Valid input, and no program: no corner to cut, nothing reachable, no pass."""

    exit_code = EXIT_NOTHING


class ProgramSyntaxError(InputError):
    """A syntax error in an APT-like part program; names the line and column."""

    def __init__(self, message: str, line: int, column: int, source: str = "<program>"):
        super().__init__(f"{source}:{line}:{column}: {message}")
        self.line = line
        self.column = column


def require(name: str, value, kinds, what: str):
    """``value`` when it is one of ``kinds``, else InputError naming the parameter: "name
    must be what, got TYPE" (the API's wrong argument types, never a bare TypeError)."""
    if not isinstance(value, kinds):
        raise InputError(f"{name} must be {what}, got {type(value).__name__}")
    return value
