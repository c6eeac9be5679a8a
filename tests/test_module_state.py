"""No hidden state at module level (issue 38): no module-level container is changed by a
function, except those an owner is documented for here.

A module-level dict, list, set or weak dictionary named in capitals (``_CACHE``,
``TABLE``) that a function assigns into, deletes from or calls a mutating method on is a
cache or a registry shared by every caller of the process: per-part data hangs on the
part (``Part.derived``, ``FaceSurface.derived``), pools on a ``kept_pools()`` block.
Tables filled once at import (``COLUMNS``) are constants.
"""

from __future__ import annotations

import ast
import re

from test_architecture import MODULES

UPPER = re.compile(r"^_?[A-Z][A-Z0-9_]*$")
CONTAINERS = {"dict", "list", "set", "WeakKeyDictionary", "WeakValueDictionary", "WeakSet",
              "defaultdict", "OrderedDict", "deque", "Counter"}
MUTATORS = {"append", "extend", "insert", "add", "update", "setdefault", "pop", "popitem",
            "clear", "remove", "discard", "appendleft", "popleft", "__setitem__"}
OWNED = {
    "cadcnc.parallel.pool._IN_WORKER":
        "a worker process: the part its pool's initializer rebuilt, for the worker's life",
    "cadcnc.ops.run.REGISTRY":
        "the operations module: each record type's planner, registered once at its import",
}
"""Module-level containers that functions change, with their owner and lifetime."""


def _is_container(value: ast.expr | None) -> bool:
    if isinstance(value, (ast.Dict, ast.List, ast.Set, ast.DictComp, ast.ListComp, ast.SetComp)):
        return True
    if isinstance(value, ast.Call):
        f = value.func
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
        return name in CONTAINERS
    return False


def module_containers(tree: ast.Module) -> set[str]:
    """Capitalised names a module binds to a container at its top level."""
    out = set()
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, ast.AnnAssign) else []
        for t in targets:
            if isinstance(t, ast.Name) and UPPER.match(t.id) and _is_container(node.value):
                out.add(t.id)
    return out


def _root(node: ast.expr) -> str | None:
    while isinstance(node, (ast.Subscript, ast.Attribute)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def mutated_in_functions(tree: ast.Module, names: set[str]) -> set[str]:
    """Which of ``names`` a function (or method) of the module changes."""
    out = set()
    for fn in ast.walk(tree):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        for node in ast.walk(fn):
            if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign, ast.Delete)):
                targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) \
                    else [node.target]
                out |= {_root(t) for t in targets
                        if isinstance(t, ast.Subscript) and _root(t) in names}
                if isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Name) \
                        and node.target.id in names:
                    out.add(node.target.id)
            elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr in MUTATORS and _root(node.func.value) in names:
                out.add(_root(node.func.value))
    return out


def hidden_state() -> dict[str, str]:
    found = {}
    for name, path in MODULES.items():
        tree = ast.parse(path.read_text())
        for var in mutated_in_functions(tree, module_containers(tree)):
            found[f"{name}.{var}"] = str(path)
    return found


def test_no_module_level_mutable_state_without_a_documented_owner():
    assert sorted(set(hidden_state()) - set(OWNED)) == []


def test_every_documented_owner_is_still_needed():
    assert sorted(set(OWNED) - set(hidden_state())) == []


def test_the_scan_sees_a_cache():
    tree = ast.parse("_CACHE: dict = {}\nTABLE = {}\nTABLE['a'] = 1\n"
                     "def get(k):\n    return _CACHE.setdefault(k, [])\n")
    assert mutated_in_functions(tree, module_containers(tree)) == {"_CACHE"}
