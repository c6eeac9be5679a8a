"""``python -m benchmarks.profile.child OUT.json [--tree DIR] -- ARGS...``: run ``cadcnc
ARGS`` in this process under :mod:`.hooks` and write what they measured (and the exit
code, the total CPU seconds) to OUT.json. ``--tree DIR``: run the cadcnc of another
checkout (its ``cadcnc/``, and ``cli/`` in checkouts older than the round that moved it
into the package), e.g. the previous commit's, for a comparison."""

from __future__ import annotations

import importlib.util
import json
import sys
import time
from pathlib import Path


def _use_tree(tree: str) -> None:
    """Import ``cadcnc`` and ``cadcnc.cli`` from the checkout ``tree``."""
    sys.path.insert(0, tree)
    spec = importlib.util.spec_from_file_location(
        "cadcnc", f"{tree}/cadcnc/__init__.py", submodule_search_locations=[f"{tree}/cadcnc"])
    module = importlib.util.module_from_spec(spec)
    sys.modules["cadcnc"] = module
    spec.loader.exec_module(module)
    where = f"{tree}/cli" if Path(f"{tree}/cli/__init__.py").is_file() else f"{tree}/cadcnc/cli"
    spec = importlib.util.spec_from_file_location(
        "cadcnc.cli", f"{where}/__init__.py", submodule_search_locations=[where])
    cli = importlib.util.module_from_spec(spec)
    sys.modules["cadcnc.cli"] = cli
    spec.loader.exec_module(cli)
    module.cli = cli


def main(argv: list[str]) -> int:
    t0 = time.process_time()
    out, rest = argv[0], argv[1:]
    tree = None
    if rest[:1] == ["--tree"]:
        tree, rest = rest[1], rest[2:]
    if rest[:1] == ["--"]:
        rest = rest[1:]
    from . import hooks

    report = hooks.install()
    if tree is not None:
        _use_tree(tree)
    from cadcnc.cli.app import main as cadcnc

    code = cadcnc(rest)
    data = report.as_dict()
    data.update(code=code, cpu=time.process_time() - t0, argv=rest, tree=tree)
    with open(out, "w") as f:
        json.dump(data, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
