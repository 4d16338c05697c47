"""One definition of the inference settings: defaults, ranges and the validator agree."""

from __future__ import annotations

import dataclasses

import pytest

from lsys_core.errors import InferenceError
from lsys_core.hierarchy.rules import Weights
from lsys_core.pipeline import InferenceSettings
from lsys_core.settings import SETTINGS, check, setting


def test_every_setting_is_a_field_with_its_default():
    fields = {f.name: f.default for f in dataclasses.fields(InferenceSettings)}
    for s in SETTINGS:
        assert fields[s.name] == s.default
    assert Weights() == Weights(*(setting(n).default for n in ("wn", "wh", "wphi", "wl")))


@pytest.mark.parametrize("spec", SETTINGS, ids=lambda s: s.name)
def test_slider_ends_and_range_ends_are_what_the_validator_accepts(spec):
    for value in (spec.slider_low(), spec.slider_high, spec.high, spec.default):
        InferenceSettings(**{spec.name: value}).validated()
    outside = [spec.high * 1.01 + 0.01, float("nan"), spec.low - 0.01]
    if spec.low_open:
        outside.append(spec.low)
    for value in outside:
        assert check(spec.name, value) is not None
        with pytest.raises(InferenceError, match=spec.name):
            InferenceSettings(**{spec.name: value}).validated()
