"""The package's surface: everything public has a docstring, and the type stubs name exactly
what the compiled module has."""

import ast
import inspect
from pathlib import Path

import shapectl
from shapectl import _shapectl

STUBS = Path(shapectl.__file__).with_name("_shapectl.pyi")


def public(names):
    return {n for n in names if not n.startswith("_")}


def stub_classes():
    tree = ast.parse(STUBS.read_text())
    classes, functions = {}, set()
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign):
                    members.add(item.target.id)
            classes[node.name] = members
        elif isinstance(node, ast.FunctionDef):
            functions.add(node.name)
    return classes, functions


def test_the_stubs_name_exactly_the_modules_classes_functions_and_members():
    classes, functions = stub_classes()
    compiled = {n: getattr(_shapectl, n) for n in public(dir(_shapectl))}
    assert set(classes) == {n for n, v in compiled.items() if inspect.isclass(v)}
    assert functions == {n for n, v in compiled.items() if not inspect.isclass(v)}
    for name, members in classes.items():
        if name == "SolverError":
            continue
        assert public(members) == public(vars(compiled[name])), name
    assert set(shapectl.__all__) == set(compiled)


def documented(name, value):
    """Whether the docstring says more than pybind11's generated signature lines."""
    doc = getattr(value, "__doc__", None) or ""
    lines = [line for line in doc.splitlines()
             if line.strip() and not line.lstrip("0123456789. ").startswith(name + "(")
             and line != "Overloaded function."]
    return bool(lines)


def test_everything_public_has_a_docstring():
    undocumented = []
    for name in public(dir(_shapectl)):
        value = getattr(_shapectl, name)
        if not documented(name, value):
            undocumented.append(name)
        if inspect.isclass(value) and value is not shapectl.SolverError:
            for member, attribute in vars(value).items():
                if not member.startswith("_") and not documented(member, attribute):
                    undocumented.append(f"{name}.{member}")
    assert undocumented == []
