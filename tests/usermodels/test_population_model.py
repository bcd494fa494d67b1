"""Populations in user-model files: subgroups with shares, parameters drawn per person, their
correlations (Gaussian copula), strict validation with the TOML key of each mistake, and
draws that depend on (seed, user) only."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from opspec.engine.random import user_stream
from opspec.errors import UserModelError
from opspec.usermodels import load_user_model

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "specs" / "medication_dispenser.population.toml"
USERS = REPO / "specs" / "medication_dispenser.users.toml"
MANUAL = ["hear_alarm", "walk_to_dispenser", "press_report", "press_wrong_button", "take_pill"]
CHOICES = {"choose_button": ["press_report", "press_wrong_button"]}

OMISSION = "activities.hear_alarm.omission.probability"


@pytest.fixture(autouse=True)
def _specs_may_be_extended(monkeypatch: pytest.MonkeyPatch) -> None:
    """The population files below (in tmp_path) extend the dispenser's model in specs/: a
    folder a user model may name only when OPSPEC_EXTERNAL_PATH allows it."""
    monkeypatch.setenv("OPSPEC_EXTERNAL_PATH", str(USERS.parent))
WALK = "activities.walk_to_dispenser.duration.median"


def write(tmp_path: Path, body: str, name: str = "people.toml") -> Path:
    """A population file extending the reference dispenser user."""
    path = tmp_path / name
    path.write_text(f'extends = "{USERS.as_posix()}"\n{body}', encoding="utf-8")
    return path


def test_the_example_population_declares_three_subgroups_with_their_own_variation():
    model = load_user_model(EXAMPLE)
    population = model.population
    assert population is not None and model.varies
    assert population.names == ("independent", "MCI", "frail")
    assert [g.share for g in population.subgroups] == [0.7, 0.2, 0.1]
    independent, mci, frail = population.subgroups
    # inherited from the top level unless the subgroup replaces it
    assert [v.name for v in independent.varied] == [OMISSION, WALK, "modifier.duration_factor"]
    by_name = {g.name: {v.name: v.distribution for v in g.varied} for g in population.subgroups}
    assert by_name["independent"][OMISSION].mean == pytest.approx(0.15)
    assert by_name["MCI"][OMISSION].mean == pytest.approx(0.25)
    assert by_name["frail"][OMISSION].mean == pytest.approx(0.15)
    assert by_name["frail"][WALK].quantile(0.5) == pytest.approx(120.0)
    # Spearman 0.3 is the Gaussian copula's r = 2 sin(pi 0.3 / 6) (Kruskal 1958)
    assert independent.correlation[0, 2] == pytest.approx(2 * math.sin(math.pi * 0.3 / 6))
    # MCI applies the mci preset: its walk has the preset's slow tail, the others do not
    assert mci.model.activities["walk_to_dispenser"].duration.kind == "with_tail"
    assert frail.model.activities["walk_to_dispenser"].duration.kind == "lognormal"
    # every subgroup covers the spec's lane
    assert model.validate_against(MANUAL, choices=CHOICES) == []


def test_a_person_gets_the_drawn_values_in_their_model():
    model = load_user_model(EXAMPLE)
    person = model.individual(3, 17)
    again = model.individual(3, 17)
    assert person.subgroup == again.subgroup and dict(person.parameters) == dict(
        again.parameters)
    p = person.parameters
    assert person.model.activities["hear_alarm"].omission.probability == p[OMISSION]
    walk = person.model.activities["walk_to_dispenser"].duration
    base = walk.base if walk.kind == "with_tail" else walk
    # the drawn median, then the person's pace (modifier.duration_factor) on top
    assert base.quantile(0.5) == pytest.approx(p[WALK] * p["modifier.duration_factor"])
    # another user is another person
    assert dict(model.individual(3, 18).parameters) != dict(p)


def test_a_model_without_variation_is_the_same_person_for_everyone():
    model = load_user_model(USERS)
    assert model.population is None and not model.varies
    person = model.individual(5, 9)
    assert person.model is model and person.subgroup is None and not person.parameters
    # the performer draws from the user's own stream, untouched by any population draw
    performer = model.performer_for(5, 9)
    expected = user_stream(5, 9)
    assert performer.rng.bit_generator.state == expected.bit_generator.state


def test_drawing_people_does_not_move_the_users_behaviour_stream():
    model = load_user_model(EXAMPLE)
    performer = model.performer_for(0, 4)
    assert performer.rng.bit_generator.state == user_stream(0, 4).bit_generator.state


def test_subgroup_shares_are_realised(tmp_path):
    """3,000 people of the example: the subgroup counts fit the multinomial of the shares
    (Pearson chi-square, 2 df), and each share lies in its exact 99.9 % interval."""
    population = load_user_model(EXAMPLE).population
    n = 3000
    counts = {name: 0 for name in population.names}
    from opspec.engine.random import named_stream

    for user in range(n):   # the subgroup is the first draw of the person's stream
        counts[population.subgroup(float(named_stream(1, "population", (user,)).random())
                                   ).name] += 1
    shares = [g.share for g in population.subgroups]
    observed = [counts[name] for name in population.names]
    assert stats.chisquare(observed, [s * n for s in shares]).pvalue > 0.001
    for k, share in zip(observed, shares, strict=True):
        ci = stats.binomtest(k, n).proportion_ci(0.999, method="exact")
        assert ci.low <= share <= ci.high
    # and Population.draw picks the same subgroups
    people = [population.draw(1, user).subgroup for user in range(200)]
    assert people == [population.subgroup(float(named_stream(1, "population", (u,)).random())
                                          ).name for u in range(200)]


@pytest.mark.parametrize("kind, stated, transform, sd_z", [
    # Fisher z of a sample Spearman has sd about sqrt(1.06 / (n - 3)) (Fieller, Hartley &
    # Pearson 1957), of a sample Kendall tau about sqrt(0.437 / (n - 4)), of a Pearson
    # correlation 1 / sqrt(n - 3)
    ("spearman", 0.6, lambda x, y: stats.spearmanr(x, y).statistic, 1.06),
    ("kendall", -0.4, lambda x, y: stats.kendalltau(x, y).statistic, 0.437),
    ("gaussian", 0.5, None, 1.0),
])
def test_correlated_parameters_have_the_requested_correlation(tmp_path, kind, stated,
                                                               transform, sd_z):
    path = write(tmp_path, f'''
[vary.activities.hear_alarm.omission]
probability = {{ kind = "beta", a = 2, b = 10 }}
[vary.activities.walk_to_dispenser.duration]
median = {{ kind = "lognormal", median = 60, sigma = 0.3 }}
[[correlations]]
parameters = ["{OMISSION}", "{WALK}"]
{kind} = {stated}
''')
    population = load_user_model(path).population
    n = 1500
    drawn = [population.draw(7, u).parameters for u in range(n)]
    x = np.array([d[OMISSION] for d in drawn])
    y = np.array([d[WALK] for d in drawn])
    if transform is None:       # the copula's r: the Pearson correlation of normal scores
        got = stats.pearsonr(stats.norm.ppf(stats.beta(2, 10).cdf(x)),
                             np.log(y / 60) / 0.3).statistic
    else:
        got = transform(x, y)
    tolerance = 4 * math.sqrt(sd_z / (n - 3))
    assert abs(math.atanh(got) - math.atanh(stated)) < tolerance
    # the marginals stay what the file says (Kolmogorov-Smirnov)
    assert stats.kstest(x, stats.beta(2, 10).cdf).pvalue > 0.001
    assert stats.kstest(y, stats.lognorm(s=0.3, scale=60).cdf).pvalue > 0.001


def test_a_population_composed_with_a_modifier_slows_each_person_after_the_draw():
    people = load_user_model(f"{EXAMPLE},older-adults")
    plain = load_user_model(EXAMPLE)
    for user in range(5):
        slowed, person = people.individual(2, user), plain.individual(2, user)
        assert dict(slowed.parameters) == dict(person.parameters)
        a = slowed.model.activities["take_pill"].duration
        b = person.model.activities["take_pill"].duration
        assert a.mean == pytest.approx(1.5 * b.mean)      # older-adults: durations x 1.5


def test_routine_window_times_may_vary_and_wrap_around_midnight(tmp_path):
    path = write(tmp_path, '''
[[routine.windows]]
name = "asleep"
start = "23:00"
end = "07:00"
notice_factor = 0.3
[vary.routine.windows.asleep]
start = { kind = "normal", mean = "23:30", sd = 3600 }
''')
    model = load_user_model(path)
    starts = [model.individual(0, u).model.routine.windows[0].start for u in range(300)]
    assert all(0 <= s < 86400 for s in starts)
    assert any(s < 3 * 3600 for s in starts)       # some go to bed after midnight
    assert min(abs(s - 84600) for s in starts) < 600


def test_a_lognormal_mean_varies_with_sigma_kept(tmp_path):
    path = write(tmp_path, '''
[vary.activities.take_pill.duration]
mean = { kind = "gamma", mean = 30, sd = 5 }
''')
    model = load_user_model(path)
    person = model.individual(0, 0)
    pill = person.model.activities["take_pill"].duration
    assert pill.mean == pytest.approx(person.parameters["activities.take_pill.duration.mean"])
    assert pill.sigma == 0.4


BAD = {
    "shares": ('''
[subgroups.a]
share = 0.7
[subgroups.b]
share = 0.25
''', r"people.toml:3: subgroups: shares add up to 0.95, not 1 \(a 0.7, b 0.25\)"),
    "share-range": ('[subgroups.a]\nshare = 70\n',
                    r"people.toml:3: subgroups.a.share: must be a share in \(0, 1\]"),
    "not-psd": (f'''
[vary.activities.hear_alarm.omission]
probability = {{ kind = "beta", a = 2, b = 10 }}
[vary.activities.walk_to_dispenser.duration]
median = {{ kind = "lognormal", median = 60, sigma = 0.3 }}
sigma = {{ kind = "gamma", mean = 0.6, sd = 0.1 }}
[[correlations]]
parameters = ["{OMISSION}", "{WALK}"]
gaussian = 0.9
[[correlations]]
parameters = ["{WALK}", "activities.walk_to_dispenser.duration.sigma"]
gaussian = 0.9
[[correlations]]
parameters = ["{OMISSION}", "activities.walk_to_dispenser.duration.sigma"]
gaussian = -0.9
''', (r"people.toml:8: correlations: the correlations cannot hold together: their matrix is "
        r"not positive semi-definite \(smallest eigenvalue -0.8")),
    "probability-support": ('''
[vary.activities.hear_alarm.omission]
probability = { kind = "lognormal", median = 0.1, sigma = 0.5 }
''', (r"people.toml:4: vary.activities.hear_alarm.omission.probability: lognormal \(median 0.1, "
        r"sigma 0.5\) draws values up to inf .*must be a probability in \[0, 1\].*beta")),
    "negative-median": ('''
[vary.activities.walk_to_dispenser.duration]
median = { kind = "normal", mean = 60, sd = 20 }
''', (r"vary.activities.walk_to_dispenser.duration.median: normal \(mean 60, sd 20\) draws "
        r"values down to -inf.*truncate the normal")),
    "modifier-notice": ('''
[vary.modifier]
notice_factor = { kind = "gamma", mean = 0.9, sd = 0.05 }
''', r"vary.modifier.notice_factor: gamma .* draws values up to inf.*must be in \[0, 1\]"),
    "unknown-activity": ('''
[vary.activities.hear_alrm.omission]
probability = { kind = "beta", a = 2, b = 10 }
''', r"vary.activities.hear_alrm.omission.probability: the model has no activity 'hear_alrm'"),
    "no-omission": ('''
[vary.activities.take_pill.omission]
probability = { kind = "beta", a = 2, b = 10 }
''', r"vary.activities.take_pill.omission.probability: the activity has no omission to vary"),
    "not-a-number": ('''
[vary.activities.take_pill]
duration = { kind = "lognormal", median = 20, sigma = 0.3 }
''', r"vary.activities.take_pill.duration: a duration varies by one of its parameters"),
    "value-not-distribution": ('''
[vary.activities.hear_alarm.omission]
probability = 0.2
''', r"vary.activities.hear_alarm.omission.probability: must be a per-user distribution"),
    "beta-sd": ('''
[vary.activities.hear_alarm.omission]
probability = { kind = "beta", mean = 0.1, sd = 0.4 }
''', r"vary.activities.hear_alarm.omission.probability.sd: must be < sqrt\(mean \(1 - mean\)\)"),
    "kind": ('''
[vary.activities.hear_alarm.omission]
probability = { kind = "logitnormal", mean = 0.1, sd = 0.04 }
''', r"omission.probability.kind: unknown per-user distribution 'logitnormal'"),
    "correlation-not-varied": (f'''
[vary.activities.hear_alarm.omission]
probability = {{ kind = "beta", a = 2, b = 10 }}
[[correlations]]
parameters = ["{OMISSION}", "{WALK}"]
spearman = 0.3
''', (r"correlations\[0\].parameters: activities.walk_to_dispenser.duration.median is not "
        r"varied")),
    "correlation-twice": (f'''
[vary.activities.hear_alarm.omission]
probability = {{ kind = "beta", a = 2, b = 10 }}
[vary.activities.walk_to_dispenser.duration]
median = {{ kind = "lognormal", median = 60, sigma = 0.3 }}
[[correlations]]
parameters = ["{OMISSION}", "{WALK}"]
spearman = 0.3
[[correlations]]
parameters = ["{WALK}", "{OMISSION}"]
spearman = 0.2
''', r"correlations\[1\]: repeats the correlation"),
    "correlation-range": (f'''
[vary.activities.hear_alarm.omission]
probability = {{ kind = "beta", a = 2, b = 10 }}
[vary.activities.walk_to_dispenser.duration]
median = {{ kind = "lognormal", median = 60, sigma = 0.3 }}
[[correlations]]
parameters = ["{OMISSION}", "{WALK}"]
spearman = 1.3
''', r"people.toml:9: correlations\[0\].spearman: must be a correlation in \[-1, 1\]"),
    "subgroup-key": ('[subgroups.a]\nshare = 1.0\nshares = 2\n',
                     r"people.toml:4: subgroups.a.shares: unknown key"),
    "subgroup-activity": ('''
[subgroups.a]
share = 1.0
[subgroups.a.activities.take_pill]
duration = { kind = "lognormal", median = 20, sigma = -1 }
''', r"people.toml:6: subgroups.a.activities.take_pill.duration.sigma: must be > 0"),
    "subgroup-vary": ('''
[subgroups.a]
share = 1.0
[subgroups.a.vary.activities.hear_alarm.omission]
probability = { kind = "uniform", low = 0.1, high = 1.5 }
''', (r"subgroups.a.vary.activities.hear_alarm.omission.probability: uniform .* draws values "
        r"up to 1.5 .*\(subgroup a\)")),
    "window": ('''
[vary.routine.windows.asleep]
start = { kind = "normal", mean = 0, sd = 1 }
''', r"vary.routine.windows.asleep.start: the model has no routine window 'asleep'"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_population_names_the_key_and_the_fix(tmp_path, case):
    body, message = BAD[case]
    with pytest.raises(UserModelError, match=message) as caught:
        load_user_model(write(tmp_path, body))
    assert caught.value.hint or "hint" not in message


def test_two_populations_do_not_compose(tmp_path):
    other = tmp_path / "more.toml"
    other.write_text('[vary.activities.take_pill.duration]\n'
                     'median = { kind = "lognormal", median = 20, sigma = 0.2 }\n',
                     encoding="utf-8")
    with pytest.raises(UserModelError, match=r"more.toml:1: vary: this file declares a "
                       "population on top of the population of"):
        load_user_model(f"{EXAMPLE},{other}")
