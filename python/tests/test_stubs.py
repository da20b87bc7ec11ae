"""The stubs (`_kinergy.pyi`) are checked against the module itself: every function's
parameters, as `__text_signature__` gives them, are the stub's, in order, with the same
kinds — the stub is never a hand-kept copy that drifts."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import kinergy
from kinergy import _kinergy

STUB = Path(kinergy.__file__).with_name("_kinergy.pyi")


def stub_functions():
    tree = ast.parse(STUB.read_text())
    found = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            found.setdefault(node.name, []).append(node.args)
    return found


def stub_parameters(args: ast.arguments):
    positional = [(a.arg, "POSITIONAL_OR_KEYWORD") for a in args.posonlyargs + args.args]
    keyword = [(a.arg, "KEYWORD_ONLY") for a in args.kwonlyargs]
    return positional + keyword


def test_every_function_of_the_module_has_its_signature_in_the_stub():
    stubs = stub_functions()
    functions = [n for n, f in vars(_kinergy).items()
                 if callable(f) and not isinstance(f, type) and not n.startswith("_")]
    assert functions, "the module exports functions"
    for name in functions:
        assert name in stubs, f"{name} has no stub"
        actual = [(p.name, p.kind.name) for p in inspect.signature(getattr(_kinergy, name)).parameters.values()]
        for overload in stubs[name]:
            assert stub_parameters(overload) == actual, f"{name}: the stub's parameters differ"
