"""Compiled conditions against the tree walker, on conditions shaped like the corpus ones.

Run: ``.venv/bin/python benchmarks/bench_conditions.py``. Prints nanoseconds per evaluation
of each condition by :func:`opspec.engine.conditions.evaluate` (walks the tree on every call)
and by the closure from :func:`opspec.engine.conditions.compile_expression`, and the ratio.
"""

from __future__ import annotations

import timeit
from functools import partial

from opspec.engine.conditions import compile_expression, evaluate
from opspec.xpdl.conditions import parse_expression

DATA = {
    "status": "approved",
    "n": 2,
    "done": False,
    "amount": "1500",
    "whereToGo": "BCD",
    "order": {"total": 12.5},
}
CONDITIONS = (
    'status == "approved"',
    "n < 3 && !done",
    "amount > 1000",
    'whereToGo.indexOf("C") != -1',
    'order.total * 2 >= 25 && status.toLowerCase().equals("approved")',
    "0 <= n <= 5000 || done",
)


def main(number: int = 100_000) -> None:
    print(f"{'condition':62s} {'walk ns':>8s} {'compiled ns':>12s} {'speed-up':>8s}")
    for text in CONDITIONS:
        expr = parse_expression(text)
        compiled = compile_expression(expr)
        assert evaluate(expr, DATA) == compiled(DATA, 0.0)
        walk = min(timeit.repeat(partial(evaluate, expr, DATA), number=number, repeat=3))
        fast = min(timeit.repeat(partial(compiled, DATA, 0.0), number=number, repeat=3))
        print(
            f"{text:62s} {walk / number * 1e9:8.0f} {fast / number * 1e9:12.0f} "
            f"{walk / fast:7.1f}x"
        )


if __name__ == "__main__":
    main()
