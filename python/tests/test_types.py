# SPDX-License-Identifier: MIT
"""Type information: __all__ is the public namespace, and the .pyi stubs with py.typed are installed beside
the module and describe it (every public name, method and property, with the module's parameters)."""

import ast
import importlib.metadata
import inspect
import os

import pytest

import trivcon
import trivcon.batch

PACKAGE = os.path.dirname(trivcon.__file__)


def test_the_namespace_is_all():
    public = {name for name in dir(trivcon) if not name.startswith("_")}
    assert public <= set(trivcon.__all__), f"public names not in __all__: {sorted(public - set(trivcon.__all__))}"
    assert len(set(trivcon.__all__)) == len(trivcon.__all__)
    for name in trivcon.__all__:
        assert hasattr(trivcon, name), name
    for leaked in ("np", "math", "Fraction", "Mapping", "numbers"):
        assert not hasattr(trivcon, leaked), leaked
    namespace = {}
    exec("from trivcon import *", namespace)
    assert set(namespace) - {"__builtins__"} == set(trivcon.__all__)


def test_stubs_and_marker_are_installed_beside_the_module():
    for name in ("py.typed", "__init__.pyi", "batch.pyi"):
        assert os.path.isfile(os.path.join(PACKAGE, name)), name
    # Installed by pip: listed in the distribution's RECORD (when it is installed, not run from the checkout).
    try:
        files = {str(f) for f in importlib.metadata.files("trivcon") or []}
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("trivcon is not installed as a distribution")
    assert {"trivcon/py.typed", "trivcon/__init__.pyi", "trivcon/batch.pyi"} <= files


def stub(name):
    with open(os.path.join(PACKAGE, name)) as f:
        return ast.parse(f.read())


def functions(body):
    """{name: [ast.FunctionDef, ...]} of the defs in `body` (overloads and property setters give several)."""
    out = {}
    for node in body:
        if isinstance(node, ast.FunctionDef):
            out.setdefault(node.name, []).append(node)
    return out


def is_overload(node):
    return any(isinstance(d, ast.Name) and d.id == "overload" for d in node.decorator_list)


def is_property(node):
    return any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list)


def stub_parameters(node):
    """[(name, kind, has a default)] of a stub def, as inspect names them (self left out)."""
    a = node.args
    out = []
    positional = a.posonlyargs + a.args
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    for arg, default in zip(positional, defaults):
        out.append((arg.arg, "POSITIONAL_OR_KEYWORD", default is not None))
    for arg, default in zip(a.kwonlyargs, a.kw_defaults):
        out.append((arg.arg, "KEYWORD_ONLY", default is not None))
    return [p for p in out if p[0] != "self"]


def runtime_parameters(function):
    return [(p.name, p.kind.name, p.default is not inspect.Parameter.empty) for p in inspect.signature(function).parameters.values()
            if p.name != "self"]


def check_function(defs, function, where):
    runtime = runtime_parameters(function)
    overloads = [d for d in defs if is_overload(d)]
    if not overloads:
        assert len(defs) == 1, where
        assert stub_parameters(defs[0]) == runtime, where
        return
    # Overloads: together they name exactly the runtime's parameters, each in the runtime's order.
    names = [p[0] for p in runtime]
    seen = set()
    for d in overloads:
        params = [p[0] for p in stub_parameters(d)]
        assert params == [n for n in names if n in params], where
        seen |= set(params)
    assert seen == set(names), where


def check_module(tree, module, names):
    defs = functions(tree.body)
    classes = {node.name: node for node in tree.body if isinstance(node, ast.ClassDef)}
    assigned = {t.id for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target]) if isinstance(t, ast.Name)}
    imported = {alias.asname or alias.name for node in tree.body if isinstance(node, ast.ImportFrom) for alias in node.names}
    for name in names:
        obj = getattr(module, name)
        assert name in defs or name in classes or name in assigned or name in imported, f"{module.__name__}.{name} is not in the stub"
        if inspect.isfunction(obj):
            check_function(defs[name], obj, f"{module.__name__}.{name}")
        elif inspect.isclass(obj) and name in classes and not issubclass(obj, Exception):
            members = functions(classes[name].body)
            public = {m for m in vars(obj) if not m.startswith("_")}
            stubbed = {m for m in members if not m.startswith("_")}
            assert public == stubbed, f"{name}: stub and module differ in {sorted(public ^ stubbed)}"
            for member in public:
                raw = inspect.getattr_static(obj, member)
                if isinstance(raw, property):
                    assert is_property(members[member][0]), f"{name}.{member} is a property"
                else:
                    assert not is_property(members[member][0]), f"{name}.{member} is a method"
                    check_function(members[member], raw, f"{name}.{member}")
            check_function(members.get("__init__") or [], obj.__init__, f"{name}.__init__")


def test_the_package_stub_describes_the_package():
    check_module(stub("__init__.pyi"), trivcon, trivcon.__all__)


def test_the_batch_stub_describes_the_batch():
    names = [n for n in vars(trivcon.batch) if not n.startswith("_") and getattr(getattr(trivcon.batch, n), "__module__", None) ==
             "trivcon.batch"] + ["COLUMNS", "STATUSES", "MESH_SUFFIXES", "FIELD_FORMATS"]
    check_module(stub("batch.pyi"), trivcon.batch, names)


def test_the_checker_catches_a_wrong_stub():
    """The comparison above notices a renamed parameter and a missing method."""
    tree = ast.parse("def read_mesh(path, details: bool = ...) -> None: ...\nclass Result:\n    def write_field(self, path): ...\n")
    with pytest.raises(AssertionError):
        check_module(tree, trivcon, ["read_mesh"])
    with pytest.raises(AssertionError):
        check_module(tree, trivcon, ["Result"])
