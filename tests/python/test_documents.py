"""The library's text and documents from Python: format_uncertain is the C++ formatter of
"value ± error" (core/uncertainty.hpp), the same text the CLI prints."""
import math

import pytest

import roughscope as rs


def test_the_errors_two_digits_decide_the_values_digits():
    assert rs.format_uncertain(0.29991, 0.00025) == "0.29991 ± 0.00025"
    assert rs.format_uncertain(0.2999123456, 0.000251) == "0.29991 ± 0.00025"
    assert rs.format_uncertain(1234.5678, 12.3) == "1235 ± 12"
    assert rs.format_uncertain(0.3, 0.00025) == "0.30000 ± 0.00025"
    assert rs.format_uncertain(1.5e-7, 2.3e-9) == "1.500e-07 ± 2.3e-09"


def test_without_a_usable_error_the_value_alone():
    for error in (None, 0.0, -1.0, math.nan, math.inf):
        assert rs.format_uncertain(0.2999123456, error) == "0.2999"
    assert rs.format_uncertain(0.2999123456, None, digits=10) == "0.2999123456"


def test_bad_values_are_refused():
    with pytest.raises(rs.InvalidArgument, match="value"):
        rs.format_uncertain(math.nan, 0.1)
    with pytest.raises(rs.InvalidArgument, match="digits"):
        rs.format_uncertain(0.3, None, digits=0)
    with pytest.raises(TypeError, match="value"):
        rs.format_uncertain("0.3", 0.1)
