"""Tests of diagnostics (``arrange_up.model.errors``): how they print, sort and are carried."""

from __future__ import annotations

from arrange_up.model.errors import Diagnostic, ProblemFormatError, sort_diagnostics


def test_a_diagnostic_prints_like_a_compiler_message() -> None:
    full = Diagnostic("p.yaml", 12, 19, "objects.T.shape", "unknown shape 'tea'")
    assert str(full) == "p.yaml:12:19: error: objects.T.shape: unknown shape 'tea'"
    no_column = Diagnostic("p.yaml", 3, None, "", "odd", "warning")
    assert str(no_column) == "p.yaml:3: warning: odd"
    whole_file = Diagnostic("p.yaml", None, 4, "", "no such file")
    assert str(whole_file) == "p.yaml: error: no such file"
    assert full.is_error and not no_column.is_error


def test_diagnostics_sort_in_file_order_file_level_first_and_stably() -> None:
    late = Diagnostic("a", 9, 1, "", "late")
    early_b = Diagnostic("a", 2, 5, "", "second at 2:5")
    early_a = Diagnostic("a", 2, 5, "", "first at 2:5")
    file_level = Diagnostic("a", None, None, "", "file")
    other_file = Diagnostic("b", 1, 1, "", "other file")
    ordered = sort_diagnostics([other_file, late, early_a, early_b, file_level])
    assert [d.message for d in ordered] == [
        "file",
        "first at 2:5",
        "second at 2:5",
        "late",
        "other file",
    ]


def test_problem_format_error_carries_errors_and_warnings() -> None:
    warning = Diagnostic("p.yaml", 1, 1, "x", "unknown key", "warning")
    error = Diagnostic("p.yaml", 2, 3, "name", "missing")
    refused = ProblemFormatError([warning, error])
    assert isinstance(refused, ValueError)
    assert refused.errors == (error,) and refused.warnings == (warning,)
    assert str(refused).splitlines() == [str(warning), str(error)]
