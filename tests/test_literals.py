"""Every float literal written with an exponent ``e-N`` in ``cadcnc/`` is named or explained.

A threshold written as a bare ``1e-9`` in the middle of an expression hides its unit and its
reason, and the same rule ends up written twice with nothing tying the copies together
(issue 38). Outside ``core/tolerances.py`` (the named tolerances themselves) such a literal
must be the value of a module-level UPPER_CASE constant (named where its module owns the
rule, with a comment or docstring on its unit and value) or stand on a line that carries a
``#`` comment saying what it guards and why the value is safe.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import cadcnc

PACKAGE = Path(cadcnc.__file__).parent
EXPONENT = re.compile(r"e-", re.IGNORECASE)
ALLOWED = {"core/tolerances.py"}
EXEMPT: set[str] = set()


def _upper_targets(node: ast.stmt) -> bool:
    if isinstance(node, ast.Assign):
        targets = node.targets
    elif isinstance(node, ast.AnnAssign) and node.value is not None:
        targets = [node.target]
    else:
        return False
    names = []
    for t in targets:
        names.extend(t.elts if isinstance(t, ast.Tuple) else [t])
    return all(isinstance(n, ast.Name) and n.id.isupper() for n in names)


def bare_literals(source: str) -> list[tuple[int, str]]:
    """(line, spelling) of every ``e-N`` float literal neither named nor commented."""
    tree = ast.parse(source)
    named = {id(sub) for node in tree.body if _upper_targets(node)
             for sub in ast.walk(node.value)}
    commented = {tok.start[0] for tok in tokenize.generate_tokens(io.StringIO(source).readline)
                 if tok.type == tokenize.COMMENT}
    lines = source.splitlines()
    out = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Constant) and isinstance(node.value, float)):
            continue
        if not EXPONENT.search(lines[node.lineno - 1]):
            continue   # (a float literal is on one line: no "e-" there, none in it)
        text = ast.get_source_segment(source, node) or ""
        if EXPONENT.search(text) and id(node) not in named and node.lineno not in commented:
            out.append((node.lineno, text))
    return sorted(out)


def test_the_scan_sees_bare_named_and_commented_literals():
    source = ("A = 1e-9\nB, C = 1e-3, 2e-6\nx = 1e-9\ny = 1e-300  # no / 0\n"
              "z = 0.001\ns = '1e-9'\ndef f():\n    LOCAL = 1e-12\n")
    assert bare_literals(source) == [(3, "1e-9"), (8, "1e-12")]


def test_every_exponent_literal_is_named_or_explained():
    bare = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel in ALLOWED or rel in EXEMPT:
            continue
        bare += [f"cadcnc/{rel}:{line}: {text}" for line, text in
                 bare_literals(path.read_text(encoding="utf-8"))]
    assert not bare, ("name these (a module constant with its unit and reason) or explain "
                      "them with a comment on their line:\n" + "\n".join(bare))


def test_the_kernel_mirrors_the_reference():
    """numba's cache freezes a global read from another file, so the compiled kernel keeps
    its own copy of the reference's rules: they must stay equal."""
    from cadcnc.interp import cycle, vec3
    from cadcnc.interp.kernel import cycle_math

    assert cycle_math.SINGULAR_DET == vec3.SINGULAR_DET
    assert cycle_math.PAPER_INVERSE_LIMIT == cycle.PAPER_INVERSE_LIMIT
    assert cycle_math.MAX_TURN == cycle.MAX_TURN
