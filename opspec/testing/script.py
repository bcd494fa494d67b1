"""Scripted users: they live with the other performers of the user lane, in
:mod:`opspec.usermodels.scripts`; this name stays for spec tests written against it."""

from opspec.usermodels.scripts import (
                                       DEFAULTS,
                                       Script,
                                       ScriptEntry,
                                       ScriptUser,
                                       load_script,
                                       parse_script,
                                       script_format,
)

__all__ = ["DEFAULTS", "Script", "ScriptEntry", "ScriptUser", "load_script", "parse_script",
           "script_format"]
