"""Objectives and constraints of a study: small arithmetic expressions of summary quantities.

An objective is a summary quantity (``"correlation"``) or an expression of several
(``"n_detected / simulated_time_s"``); a constraint is such an expression compared with a
number (``"correlation < 0.05"``, ``"n_detected / simulated_time_s >= 1.8e8"``).

The expressions are parsed with :mod:`ast` and evaluated by walking the tree, never with
:func:`eval`: only numbers, the names of the device's summary quantities, the operators
``+ - * / **`` (and unary ``-``, ``+``), brackets and the functions :data:`FUNCTIONS` are
accepted; anything else (attributes, calls of other names, subscripts, strings, comparisons
inside an objective) is refused with one line before anything runs.

A constraint ``E < b`` (or ``<=``) holds when ``E − b ≤ 0``; ``E > b`` (or ``>=``) when
``b − E ≤ 0``. That difference is what the optimiser receives (optuna's ``constraints_func``: a
trial is feasible when all its values are ≤ 0). Strict and non-strict comparisons are the same
for the optimiser.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass

from skygas.core.errors import InputError, require

#: The functions an expression may call, each of one argument except ``min`` and ``max``.
FUNCTIONS: dict[str, Callable[..., float]] = {
    "abs": abs,
    "sqrt": math.sqrt,
    "log": math.log,
    "log10": math.log10,
    "exp": math.exp,
    "min": min,
    "max": max,
}

_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b if b != 0 else math.copysign(math.inf, a) if a else math.nan,
    ast.Pow: lambda a, b: a**b,
}
_COMPARE = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}
_ALLOWED_TEXT = (
    "an arithmetic expression of summary quantities: numbers, names, + - * / **, brackets and "
    f"the functions {', '.join(FUNCTIONS)}"
)


def _check(node: ast.AST, field: str, text: str, names: Collection[str]) -> set[str]:
    """Refuse any node outside the whitelist; return the quantity names used."""
    if isinstance(node, ast.Constant):
        require(
            isinstance(node.value, (int, float)) and not isinstance(node.value, bool),
            field,
            text,
            _ALLOWED_TEXT,
        )
        return set()
    if isinstance(node, ast.Name):
        require(
            node.id in names,
            field,
            text,
            f"quantities of the device's summary ({node.id!r} is not one of them: "
            f"{', '.join(sorted(names))})",
        )
        return {node.id}
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return _check(node.left, field, text, names) | _check(node.right, field, text, names)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        return _check(node.operand, field, text, names)
    if (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in FUNCTIONS
        and not node.keywords
        and (len(node.args) == 1 or (node.func.id in ("min", "max") and len(node.args) >= 2))
    ):
        used: set[str] = set()
        for arg in node.args:
            used |= _check(arg, field, text, names)
        return used
    raise InputError(field, text, _ALLOWED_TEXT)


def _evaluate(node: ast.AST, values: Mapping[str, float]) -> float:
    if isinstance(node, ast.Constant):
        assert isinstance(node.value, (int, float))  # checked at parse
        return float(node.value)
    if isinstance(node, ast.Name):
        return float(values[node.id])
    if isinstance(node, ast.BinOp):
        left, right = _evaluate(node.left, values), _evaluate(node.right, values)
        try:
            return float(_BINARY[type(node.op)](left, right))
        except (OverflowError, ValueError, ZeroDivisionError):
            return math.nan
    if isinstance(node, ast.UnaryOp):
        value = _evaluate(node.operand, values)
        return -value if isinstance(node.op, ast.USub) else value
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)  # checked at parse
    args = [_evaluate(a, values) for a in node.args]
    try:
        return float(FUNCTIONS[node.func.id](*args))
    except (OverflowError, ValueError):  # log of a negative number, exp of a large one
        return math.nan


@dataclass(frozen=True)
class Expression:
    """A checked arithmetic expression of summary quantities (see the module docstring)."""

    text: str
    tree: ast.expr
    names: frozenset[str]

    def __call__(self, values: Mapping[str, float]) -> float:
        """The expression's value for the summary ``values`` (NaN where it is undefined)."""
        return _evaluate(self.tree, values)

    @property
    def key(self) -> str:
        """The expression in a normal form (same for ``a/b`` and ``a / b``)."""
        return ast.dump(self.tree)


def parse_expression(text: object, field: str, names: Collection[str]) -> Expression:
    """Parse and check an objective expression.

    Parameters
    ----------
    text : object
        The expression as written in the study file.
    field : str
        Its place in the file, for the error message (``"objective[0].expression"``).
    names : collection of str
        The quantities the device's summary holds.

    Returns
    -------
    Expression
        The checked expression.

    Raises
    ------
    InputError
        On anything but an arithmetic expression of ``names`` and numbers.
    """
    require(isinstance(text, str) and bool(text.strip()), field, text, _ALLOWED_TEXT)
    assert isinstance(text, str)  # checked just above
    try:
        tree = ast.parse(text.strip(), mode="eval").body
    except SyntaxError:
        raise InputError(field, text, _ALLOWED_TEXT) from None
    used = _check(tree, field, text, names)
    require(bool(used), field, text, "an expression of at least one summary quantity")
    return Expression(text.strip(), tree, frozenset(used))


@dataclass(frozen=True)
class Constraint:
    """``expression`` compared with ``bound``: ``upper`` for ``<``/``<=``, else a lower bound."""

    text: str
    expression: Expression
    bound: float
    upper: bool
    strict: bool = False

    def violation(self, values: Mapping[str, float]) -> float:
        """How far ``values`` are from meeting it: ≤ 0 when it holds (NaN: it cannot be told)."""
        value = self.expression(values)
        return value - self.bound if self.upper else self.bound - value


def parse_constraint(text: object, field: str, names: Collection[str]) -> Constraint:
    """Parse and check a constraint ``EXPRESSION < NUMBER`` (or ``<=``, ``>``, ``>=``).

    Parameters
    ----------
    text : object
        The constraint as written in the study file.
    field : str
        Its place in the file, for the error message.
    names : collection of str
        The quantities the device's summary holds.

    Returns
    -------
    Constraint
        The checked constraint.
    """
    allowed = "EXPRESSION < NUMBER (or <=, >, >=), e.g. 'correlation < 0.05'"
    require(isinstance(text, str), field, text, allowed)
    assert isinstance(text, str)  # checked just above
    try:
        tree = ast.parse(text.strip(), mode="eval").body
    except SyntaxError:
        raise InputError(field, text, allowed) from None
    require(
        isinstance(tree, ast.Compare) and len(tree.ops) == 1 and type(tree.ops[0]) in _COMPARE,
        field,
        text,
        allowed,
    )
    assert isinstance(tree, ast.Compare)  # checked just above
    bound_node = tree.comparators[0]
    require(not _names_in(bound_node), field, text, f"{allowed} (a number on the right)")
    _check(bound_node, field, text, ())
    bound = _evaluate(bound_node, {})
    require(math.isfinite(bound), field, text, f"{allowed} (a finite number on the right)")
    left = ast.unparse(tree.left)
    expression = parse_expression(left, field, names)
    op = tree.ops[0]
    return Constraint(
        text.strip(),
        expression,
        bound,
        upper=isinstance(op, (ast.Lt, ast.LtE)),
        strict=isinstance(op, (ast.Lt, ast.Gt)),
    )


def _names_in(node: ast.AST) -> bool:
    return any(isinstance(n, ast.Name) and n.id not in FUNCTIONS for n in ast.walk(node))


def check_consistent(constraints: list[Constraint], field: str = "study.constraints") -> None:
    """Refuse constraints on one expression that no value can meet (``x < 1`` and ``x > 2``).

    Raises
    ------
    InputError
        Naming the two constraints that contradict each other.
    """
    by_key: dict[str, list[Constraint]] = {}
    for c in constraints:
        by_key.setdefault(c.expression.key, []).append(c)
    for group in by_key.values():
        uppers = [c for c in group if c.upper]
        lowers = [c for c in group if not c.upper]
        if not uppers or not lowers:
            continue
        upper = min(uppers, key=lambda c: c.bound)
        lower = max(lowers, key=lambda c: c.bound)
        require(
            lower.bound < upper.bound
            or (lower.bound == upper.bound and not (lower.strict or upper.strict)),
            field,
            [lower.text, upper.text],
            "constraints that some value can meet (these two contradict each other)",
            "loosen or remove one of them",
        )


def _unit(node: ast.AST, unit_of_name: Callable[[str], str]) -> str | None:
    """The unit of ``node``'s value ("" for a pure number), or None where it is not derived."""
    if isinstance(node, ast.Constant):
        return ""
    if isinstance(node, ast.Name):
        return unit_of_name(node.id)
    if isinstance(node, ast.UnaryOp):
        return _unit(node.operand, unit_of_name)
    if isinstance(node, ast.BinOp):
        left, right = _unit(node.left, unit_of_name), _unit(node.right, unit_of_name)
        if left is None or right is None:
            return None
        if isinstance(node.op, (ast.Add, ast.Sub)):
            return left if left == right else None
        if left == right == "":
            return ""  # any arithmetic of pure numbers
        if isinstance(node.op, ast.Div) and left == right:
            return ""  # a quantity over one of its own unit
        # a product or quotient with a number may be a change of unit (energy_per_bit_J * 1e15
        # in fJ): not derived, rather than a unit that may be wrong
        return None
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        units = {_unit(a, unit_of_name) for a in node.args}
        if None in units or len(units) != 1:
            return None  # min(t, 1e-6): the number has no unit of its own
        (unit,) = units
        if node.func.id in ("abs", "min", "max"):
            return unit
        return "" if unit == "" else None  # sqrt, log, exp of a pure number only
    return None


def unit_of(expression: Expression, unit_of_name: Callable[[str], str]) -> str | None:
    """The unit of ``expression``'s value, from the units of the quantities it uses.

    Sums and differences of one unit keep it, as do ``abs``, ``min`` and ``max`` of it; a
    quotient of two quantities of one unit is a pure number (""), as is any arithmetic of pure
    numbers. Anything else is not derived (None; the value is then shown without a unit): a
    product with a number may be a change of unit (``energy_per_bit_J * 1e15``, in fJ), and a
    count per second (``n_detected / simulated_time_s``) has no unit in the table.

    Parameters
    ----------
    expression : Expression
        A checked expression.
    unit_of_name : callable
        The unit of each quantity name ("" for a pure number or a count).

    Returns
    -------
    str or None
        The unit as a reader writes it ("Hz", "" for a pure number), or None.
    """
    return _unit(expression.tree, unit_of_name)
