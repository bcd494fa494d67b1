"""Where a key of a TOML file is written (:mod:`opspec.toml_lines`): every form of TOML a person
writes by hand places an error at its own line, not at a neighbour's."""

from __future__ import annotations

from pathlib import Path

from opspec.toml_lines import key_line, located, syntax_line


def _text(*lines: str) -> str:
    return "\n".join(lines) + "\n"


def test_arrays_of_tables_place_each_entry_at_its_own_lines() -> None:
    text = _text(
        "[[routine.windows]]",          # 1
        'name = "asleep"',              # 2
        'end = "07:00"',                # 3
        "",                             # 4
        "[[routine.windows]]",          # 5
        'name = "out"',                 # 6
        'end = "31:00"',                # 7
        "[routine.drift]",              # 8
        "min_notice_factor = 0.7",      # 9
    )
    assert key_line(text, "routine.windows[0].end") == 3
    assert key_line(text, "routine.windows[1]") == 5
    assert key_line(text, "routine.windows[1].end") == 7
    assert key_line(text, "routine.windows[1].start") == 5      # missing: its table
    assert key_line(text, "routine.drift.min_notice_factor") == 9


def test_a_table_under_an_array_of_tables_belongs_to_its_last_entry() -> None:
    text = _text("[[fruit]]", "name = 'apple'", "[[fruit]]", "name = 'pear'",
                 "[fruit.physical]", "colour = 'green'", "[[fruit.variety]]", "name = 'x'")
    assert key_line(text, "fruit[1].physical.colour") == 6
    assert key_line(text, "fruit[1].variety[0].name") == 8
    assert key_line(text, "fruit[0].name") == 2


def test_keys_inside_inline_tables_and_their_values() -> None:
    text = _text(
        "[activities.walk]",                                                    # 1
        "source = 'a = { not a key }'",                                         # 2
        'duration = { kind = "with_tail", base = { kind = "gamma", shape = -1 } }',  # 3
        "omission = { probability = 1.5 }",                                     # 4
    )
    assert key_line(text, "activities.walk.duration.base.shape") == 3
    assert key_line(text, "activities.walk.omission.probability") == 4
    assert key_line(text, "activities.walk.omission.reason") == 4   # not written: its table


def test_dotted_and_quoted_keys() -> None:
    text = _text(
        "[uncertainty]",                                                        # 1
        "draws = 2",                                                            # 2
        '[uncertainty.parameters."activities.walk.duration.median"]',           # 3
        "estimate = 61.9",                                                      # 4
        "[vary]",                                                               # 5
        "activities.hear.omission.probability = { kind = 'beta', a = 2, b = 9 }",  # 6
        "'quoted key' . inner = 1",                                             # 7
    )
    assert key_line(text, "uncertainty.parameters.activities.walk.duration.median.estimate") == 4
    assert key_line(text, "vary.activities.hear.omission.probability.kind") == 6
    assert key_line(text, "vary.activities.hear") == 6
    assert key_line(text, "vary.quoted key.inner") == 7


def test_multi_line_arrays_place_each_entry_and_are_no_table_headers() -> None:
    # the old scanner read the line '["a"]' of an array as the header of a table "a"
    text = _text(
        "obstacles = [            # boxes",         # 1
        "  [1.5, 1.5, 2.1, 2.3],",                  # 2
        '  ["a"]',                                  # 3
        "]",                                        # 4
        "start = [0.5, 0.5, 0.3]",                  # 5
        "windows = [",                              # 6
        "  { name = 'x' },",                        # 7
        "  { name = 'y', start = 3 },",             # 8
        "]",                                        # 9
    )
    assert key_line(text, "obstacles[1]") == 3
    assert key_line(text, "obstacles") == 1
    assert key_line(text, "start") == 5
    assert key_line(text, "windows[1].start") == 8


def test_strings_and_comments_hide_what_looks_like_keys() -> None:
    text = _text(
        'description = """',            # 1
        "[activities.walk]",            # 2: inside the string
        'duration = 3"""',              # 3: still inside
        "# [activities.take] = 1",      # 4: a comment
        "literal = '''",                # 5
        "x = 1'''",                     # 6
        "[activities.take]",            # 7
        'duration = "3 \\" = 4"',       # 8
        "kind = 'x'",                   # 9
    )
    assert key_line(text, "activities") == 7          # not 2: line 2 is in a string
    assert key_line(text, "activities.take") == 7
    assert key_line(text, "activities.take.kind") == 9
    assert key_line(text, "x") is None


def test_text_that_is_not_toml_is_scanned_without_failing() -> None:
    text = "= 3\n[unclosed\nkey = [1, 2\n{ }\nname = 'x'\n"
    assert key_line(text, "nothing") is None
    assert key_line("", "a") is None


def test_syntax_line_reads_tomllibs_message() -> None:
    assert syntax_line("Cannot overwrite a value (at line 32, column 16)") == 32
    assert syntax_line("Invalid value (at end of document)") is None


def test_located_reads_the_file_or_keeps_the_key_alone(tmp_path: Path) -> None:
    path = tmp_path / "users.toml"
    path.write_text("name = 'x'\n[activities.walk]\nduration = 3\n", encoding="utf-8")
    where = located(str(path), "activities.walk.duration.kind")
    assert (where.line, where.key, str(where)) == (
        3, "activities.walk.duration.kind", f"{path}:3: activities.walk.duration.kind")
    assert located("<toml>", "activities").line is None          # no file: no line
    assert located(str(tmp_path), "activities").line is None     # a folder is not read
    assert located(str(path), None) == located(str(path), "")
