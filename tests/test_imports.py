"""How the package imports: light at first, the rest on first use, no cycle, no import of its own
modules hidden in a function."""

import ast
import pathlib
import subprocess
import sys

import morphomap as mm

PACKAGE = pathlib.Path(mm.__file__).parent
#: Required dependencies that `import morphomap` leaves for the modules that use them.
HEAVY = ("trimesh", "matplotlib", "scipy.ndimage", "skimage", "tifffile", "meshio", "h5py", "dask", "distributed")


def modules():
    """{dotted name: parsed source} of every module of the package."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = (path.name == "__init__.py", ast.parse(path.read_text(encoding="utf-8")))
    return found


def compiled():
    """The package's compiled modules (the core)."""
    return {f"morphomap.{path.name.split('.')[0]}" for path in PACKAGE.glob("*.so")} | {
        f"morphomap.{path.name.split('.')[0]}" for path in PACKAGE.glob("*.pyd")}


def own_imports(name, is_package, node, known):
    """The package's modules (of ``known``) whose code the import statement ``node`` in module
    ``name`` needs: ``from . import x`` needs the submodule x, or the package where x is a name
    of its ``__init__``."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "morphomap"]
    if node.level == 0:
        base = node.module or ""
        if base.split(".")[0] != "morphomap":
            return []
    else:
        parts = name.split(".") if is_package else name.split(".")[:-1]
        parts = parts[: len(parts) - node.level + 1]
        base = ".".join(parts + ([node.module] if node.module else []))
    submodules = [f"{base}.{a.name}" for a in node.names if f"{base}.{a.name}" in known]
    return submodules + ([base] if node.module or len(submodules) < len(node.names) else [])


def test_import_leaves_the_heavy_modules_for_first_use():
    code = ("import sys, morphomap; heavy = " + repr(HEAVY) +
            "; print([m for m in heavy if m in sys.modules])")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "[]"


def test_every_public_name_resolves_and_is_listed():
    assert set(mm.__all__) <= set(dir(mm))
    for name in mm.__all__:
        assert getattr(mm, name) is not None, name
    assert set(mm.io.__all__) <= set(dir(mm.io))
    for name in mm.io.__all__:
        assert getattr(mm.io, name) is not None, name


def test_no_import_of_the_package_inside_a_function():
    found, hidden = modules(), []
    known = set(found) | compiled()
    for name, (is_package, tree) in found.items():
        for function in (n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))):
            for node in ast.walk(function):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    hidden += [(name, target) for target in own_imports(name, is_package, node, known)]
    # The dolfinx example runs, by its path, in a Python that need not have morphomap.
    assert hidden == [("morphomap.examples.growing_domain_fenicsx", "morphomap.examples.growing_frames")]


def test_no_import_cycle():
    found = modules()
    known = set(found) | compiled()
    graph = {name: set() for name in found}
    for name, (is_package, tree) in found.items():
        for node in tree.body:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                graph[name] |= {m for m in own_imports(name, is_package, node, known) if m in found and m != name}
    state = {}

    def visit(name, path):
        state[name] = "open"
        for target in sorted(graph[name]):
            assert state.get(target) != "open", " -> ".join(path + [target])
            if target not in state:
                visit(target, path + [target])
        state[name] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
