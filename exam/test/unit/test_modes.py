"""The two modes of the exam node: each sheet's limit, inputs and formula."""
from exam import formulas
from exam.modes import MODES


def test_default_thresholds_are_the_limits_of_the_sheets():
    # Sheet 000: the remote controller's range; sheet 001: the drone's depth rating.
    assert MODES['altitude'].default_threshold == 1300.0
    assert MODES['depth'].default_threshold == 150.0


def test_each_mode_reads_its_inputs_in_the_order_its_formula_takes_them():
    altitude, depth = MODES['altitude'], MODES['depth']
    assert [i.topic for i in altitude.inputs] == ['temperature', 'pressure']
    assert [i.why_unusable for i in altitude.inputs] == [formulas.why_unusable_temperature, formulas.why_unusable_pressure]
    assert altitude.compute is formulas.altitude
    assert [i.topic for i in depth.inputs] == ['pressure_robot', 'pressure_remote']
    assert depth.compute is formulas.depth
