"""A mean claim that held on replications that all gave the same value held on a t interval
of no width: it shows that these few replications did not differ, not a value known exactly
(docs/evaluation.md, "Intervals of no width"). A green test must not read as more than it
is: the scenario's note is listed at the end of the session and in the test's report, and
``assert_mean`` warns. The share of replications that could still give another value is the
exact (Clopper-Pearson) upper bound of 0 unlike of n, 1 − (α/2)^(1/n) (a closed form: 52 %
at 5, below 1 % from 368 at 95 %)."""

from __future__ import annotations

import warnings

import pytest

from opspec.statistics.claims import alike_caveat
from opspec.testing.assertions import AllAlikeWarning, assert_mean

ALIKE = '''
spec = "specs/dispenser.xpdl"
[[scenario]]
name = "few prompt users"
given = { user_model = "specs/dispenser.users.toml", users = 3, days = 1 }
then = ["mean doses_due <= 4 with 95% confidence",
        "mean report_latency_s >= 0 with 95% confidence"]
'''


def test_a_mean_scenario_over_replications_all_alike_says_so_at_the_end(
        project: pytest.Pytester) -> None:
    (project.path / "alike.scenario.toml").write_text(ALIKE)
    result = project.runpytest()
    result.assert_outcomes(passed=1)
    out = result.stdout.str()
    result.stdout.fnmatch_lines([
        "*= opspec: claims that held on replications all alike =*",
        ("*alike.scenario.toml:6: scenario[[]0].then[[]0]: 'mean doses_due <= 4 with 95% "
         "confidence' held, but all 3 replications gave 4: that shows no spread between them*"
         "up to 71% of replications could give another value*about 368 replications*")])
    # the users' latencies differ: that claim's interval has a width, and no note
    assert "then[1]" not in out


def test_a_failing_scenario_report_carries_the_note(project: pytest.Pytester) -> None:
    (project.path / "alike.scenario.toml").write_text(ALIKE.replace(
        '"mean report_latency_s >= 0', '"mean report_latency_s <= 0'))
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*- opspec -*", "note: *then[[]0]: 'mean doses_due <= 4*"])


class _Samples:
    """A result's per-replication values, as ``simulate`` gives them."""

    def __init__(self, values: list[float]) -> None:
        self.values = values
        self.replications = len(values)

    def samples(self, metric: str) -> list[float]:
        return self.values


def test_assert_mean_warns_when_it_passes_on_replications_all_alike() -> None:
    with pytest.warns(AllAlikeWarning, match=r"all 5 replications gave 0: .* up to 52%"):
        decision = assert_mean(_Samples([0.0] * 5), "doses_missed", at_most=1)
    assert decision.passed and decision.lo == decision.hi == 0.0


@pytest.mark.parametrize("values", [[0.0, 1.0, 0.0, 0.0, 0.0], [0.0] * 368])
def test_no_warning_when_they_differ_or_are_enough(values: list[float]) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", AllAlikeWarning)
        assert assert_mean(_Samples(values), "doses_missed", at_most=1).passed


def test_the_bound_is_the_exact_one_of_none_unlike() -> None:
    # 1 - 0.025^(1/367) = 1.0001 % and 1 - 0.025^(1/368) = 0.9974 %: 368 is the first n
    assert alike_caveat("c", [2.0] * 367, 0.95) is not None
    assert alike_caveat("c", [2.0] * 368, 0.95) is None
    # at 99 % it takes more: 1 - 0.005^(1/n) <= 1 % from n = 528
    assert alike_caveat("c", [2.0] * 527, 0.99) is not None
    assert alike_caveat("c", [2.0] * 528, 0.99) is None


def test_expect_warns_as_assert_mean_does(project: pytest.Pytester) -> None:
    project.makepyfile('''
from opspec.testing import expect

def test_mean(simulate):
    result = simulate("specs/dispenser.xpdl", users=3, days=1,
                      user_model="specs/dispenser.users.toml")
    expect(result, "mean doses_due <= 4 with 95% confidence")
''')
    result = project.runpytest()
    result.assert_outcomes(passed=1, warnings=1)
    result.stdout.fnmatch_lines([("*AllAlikeWarning: 'mean doses_due <= 4 with 95% "
                                  "confidence' held, but all 3 replications gave 4*")])
