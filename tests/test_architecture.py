"""The layout rules of docs/architecture.md, checked on the source tree.

- The interpolation core (``cadcnc/interp/``) imports no OCCT: only itself, the kernel-free
  top-level modules, the standard library, numpy and numba.
- No import cycles between cadcnc modules, function-local imports included.
- No function body over 80 lines (a few named, with their reasons); a module over 400
  lines is noted, not failed; no flat ``verification_*`` modules.
- OCCT (OCP, cadquery) only in the geometry, guard and verification stages (and the
  writers' pictures and CadQuery wires): never in ``ops/``, ``program/`` or ``controller/``.
- No private name (``_x``) imported from another module.
- Stages import only from stages before them (the order of docs/architecture.md).
"""

from __future__ import annotations

import ast
import re
import sys
import warnings
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "cadcnc"
KERNEL_FREE_TOP = {"cadcnc.core", "cadcnc.core.errors", "cadcnc.core.tolerances", "cadcnc.core.job",
                   "cadcnc.core.operations", "cadcnc.core.tool", "cadcnc.core.progress",
                   "cadcnc.core.units", "cadcnc.core.work_limits", "cadcnc.core.trim_labels",
                   "cadcnc.core.jsonable", "cadcnc.core.interrupts", "cadcnc.core.scratch"}
THIRD_PARTY_OK_IN_CORE = {"numpy", "numba"}


def module_name(path: Path) -> str:
    parts = ("cadcnc", *path.relative_to(PKG).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def sources() -> dict[str, Path]:
    files = list(PKG.rglob("*.py"))
    return {module_name(f): f for f in files if "__pycache__" not in f.parts}


MODULES = sources()


def imports(name: str) -> set[str]:
    """Every module ``name`` imports (absolute names), at any depth of the file."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            # `from . import x` / `from .pkg import mod`: x may itself be a module
            out |= {f"{mod}.{a.name}" for a in node.names if f"{mod}.{a.name}" in MODULES}
    return out


def internal(name: str) -> set[str]:
    """The cadcnc modules ``name`` depends on (a package import counts as its __init__)."""
    return {m for m in imports(name) if m in MODULES and m != name}


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n.startswith("cadcnc.interp")))
def test_interpolation_core_imports_no_occt(name):
    for mod in imports(name):
        top = mod.split(".")[0]
        if top == "cadcnc":
            assert mod.startswith("cadcnc.interp") or mod in KERNEL_FREE_TOP, (name, mod)
        else:
            assert top in sys.stdlib_module_names or top in THIRD_PARTY_OK_IN_CORE, (name, mod)


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n.startswith("cadcnc.controller")))
def test_controller_imports_no_occt_and_no_hal(name):
    """The controller (feed planning, stream) takes steppers from its caller: no OCCT, no
    HAL; it reads the interpolation core, programs and the shared vocabulary."""
    for mod in imports(name):
        top = mod.split(".")[0]
        if top == "cadcnc":
            assert mod.startswith(("cadcnc.controller", "cadcnc.interp", "cadcnc.program")) \
                or mod in KERNEL_FREE_TOP, (name, mod)
        else:
            assert top in sys.stdlib_module_names or top in THIRD_PARTY_OK_IN_CORE, (name, mod)


def test_kernel_free_top_level_modules_import_no_occt():
    for name in KERNEL_FREE_TOP & set(MODULES):
        for mod in imports(name):
            top = mod.split(".")[0]
            assert top not in ("OCP", "cadquery"), (name, mod)
            if top == "cadcnc":
                assert mod in KERNEL_FREE_TOP, (name, mod)


def test_no_import_cycles():
    graph = {n: internal(n) for n in MODULES}
    # a package's __init__ re-exporting its submodules is not a dependency of them
    for n, deps in graph.items():
        graph[n] = {d for d in deps if not n.startswith(d + ".")}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for d in sorted(graph[n]):
            if state.get(d) == 1:
                cycle = stack[stack.index(d):] + [d]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if d not in state:
                visit(d)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)


FUNCTION_LINES = 80
"""The longest function or method body (lines, from its first statement to its last)."""
LONG_FUNCTIONS = {
    # name: (lines today, why it stays whole)
    "cadcnc.verification.reference.check_reference": (
        112, "one sequential comparison with OCCT's intersection curves (match, resample, "
             "measure, judge the ends), every step reading the state the last one left"),
    "cadcnc.verification.table.format_table": (
        86, "the report's text, one line of the table after another: a split would cut "
            "one table in two places"),
    "cadcnc.cli.app.build_parser": (
        87, "the command line's subcommands declared in one place, in the order --help "
            "shows them"),
}
"""Functions allowed over FUNCTION_LINES, each at most as long as it is today."""
MODULE_LINES = 400
"""A module over this many lines gets a warning, not a failure: split it where it has two
subjects, not to pass a count."""


def function_lengths() -> dict[str, int]:
    """Every function and method of the package: its body's length in lines."""
    out = {}
    for name, path in MODULES.items():
        tree = ast.parse(path.read_text())
        parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                qual, up = [node.name], parents.get(node)
                while up is not None and not isinstance(up, ast.Module):
                    if isinstance(up, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                        qual.insert(0, up.name)
                    up = parents.get(up)
                out[f"{name}.{'.'.join(qual)}"] = node.end_lineno - node.body[0].lineno + 1
    return out


def test_functions_are_short():
    """No function body over FUNCTION_LINES lines, but for LONG_FUNCTIONS (none growing)."""
    long = {n: k for n, k in function_lengths().items() if k > FUNCTION_LINES}
    assert {n: k for n, k in long.items()
            if n not in LONG_FUNCTIONS or k > LONG_FUNCTIONS[n][0]} == {}


def test_long_function_allowances_are_still_needed():
    """An allowance goes when its function is split (or renamed, or gone)."""
    lengths = function_lengths()
    assert [n for n in LONG_FUNCTIONS if lengths.get(n, 0) <= FUNCTION_LINES] == []


def test_long_modules_are_noted():
    """Modules over MODULE_LINES lines: a warning in the summary (``-ra``), not a failure."""
    long = {n: len(p.read_text().splitlines()) for n, p in MODULES.items()}
    over = sorted(f"{n} ({k})" for n, k in long.items() if k > MODULE_LINES)
    if over:
        warnings.warn(f"modules over {MODULE_LINES} lines: " + ", ".join(over), stacklevel=1)


def test_no_flat_verification_modules():
    assert not list(PKG.glob("verification_*.py"))
    assert (PKG / "verification" / "__init__.py").is_file()


NO_OCCT_STAGES = ("cadcnc.ops", "cadcnc.program", "cadcnc.controller", "cadcnc.simulation")


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n.startswith(NO_OCCT_STAGES)))
def test_operations_program_and_controller_import_no_occt(name):
    for mod in imports(name):
        assert mod.split(".")[0] not in ("OCP", "cadquery"), (name, mod)


@pytest.mark.parametrize("name", sorted(n for n in MODULES
                                        if n.startswith("cadcnc.verification")))
def test_verification_imports_nothing_from_the_guard(name):
    """The gate is a second opinion: it shares no code with the guard it checks."""
    assert not [m for m in internal(name) if m.startswith("cadcnc.guard")], name


def test_no_private_name_imported_across_modules():
    found = []
    for name, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                found += [f"{name}: {a.name}" for a in node.names
                          if a.name.startswith("_") and not a.name.startswith("__")]
    assert found == []


STAGES = ["core", "interp", "geometry", "parallel", "guard", "program", "ops", "controller",
          "io", "verification", "simulation", "apt", "pipeline", "batch", "cli", "testing"]
"""The data flow, in the order the code has (docs/architecture.md): a stage imports only from
itself and the stages before it. ``testing`` (the independent references the tests and the
benchmarks share) comes last: nothing in cadcnc imports it."""
TOP = {"cadcnc", "cadcnc.__main__"}
"""The modules outside any stage: the package's API and its ``python -m`` entry."""


def stage(name: str) -> int | None:
    parts = name.split(".")
    return STAGES.index(parts[1]) if len(parts) > 1 and parts[1] in STAGES else None


def test_every_module_is_in_a_stage():
    assert sorted(n for n in MODULES if stage(n) is None and n not in TOP) == []


def test_nothing_imports_upward():
    upward = []
    for name in MODULES:
        mine = stage(name)
        if mine is None:
            continue
        for dep in internal(name):
            theirs = stage(dep)
            if theirs is not None and theirs > mine:
                upward.append(f"{name} -> {dep}")
    assert upward == []


def test_exit_codes_come_from_their_one_definition():
    """The commands return the codes of cadcnc.core.errors (EXIT_*), never a literal other than
    0: the codes are defined once (docs/reliability.md)."""
    literal = []
    for name, path in MODULES.items():
        if not (name.startswith("cadcnc.cli") or name.endswith("__main__")):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Return) or node.value is None:
                continue
            value = node.value
            branches = [value.body, value.orelse] if isinstance(value, ast.IfExp) else [value]
            literal += [f"{name}:{node.lineno}: {b.value}" for b in branches
                        if isinstance(b, ast.Constant) and type(b.value) is int and b.value]
    assert literal == []


def test_the_map_lists_the_stages_in_order():
    """docs/architecture.md's map names every stage of STAGES, in that order (its table's
    first column, ``core/`` ...). A stage the map lists before its folder exists (one being
    built on another branch) is passed over until the folder comes."""
    doc = (PKG.parent / "docs" / "architecture.md").read_text()
    listed = re.findall(r"^\| `(\w+)/` \|", doc, re.M)
    assert [s for s in listed if (PKG / s).is_dir()] == STAGES


def test_the_cli_has_no_function_local_imports():
    """The command line imports at the top of its modules only; the one lazy import is the
    command table's (cadcnc/cli/commands.py, importlib on dispatch)."""
    local = []
    for name, path in MODULES.items():
        if not name.startswith("cadcnc.cli"):
            continue
        for fn in ast.walk(ast.parse(path.read_text())):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                local += [f"{name}.{fn.name}: line {node.lineno}" for node in ast.walk(fn)
                          if isinstance(node, (ast.Import, ast.ImportFrom))]
    assert local == []


HANDLER_LINES = 30
"""The most lines a command's handler may have: parse -> Job -> one pipeline call -> print."""


def test_each_command_handler_is_short():
    from cadcnc.cli.commands import HANDLERS

    long = {}
    for command, where in HANDLERS.items():
        module, _, function = where.partition(":")
        tree = ast.parse(MODULES[module].read_text())
        fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == function)
        if fn.end_lineno - fn.lineno + 1 > HANDLER_LINES:
            long[command] = fn.end_lineno - fn.lineno + 1
    assert long == {}
