"""The fleet launcher's command line: its defaults are the exam node's, and one pair is a fleet.

The rest of exam.fleet is tested where it runs: the ops suite's test_fleet_args.py (pair arguments) and
test_fleet.py (a real fleet under roslaunch).
"""
import pytest

from exam.fleet import pair_arguments, parse_args


def test_command_line_defaults_are_those_of_the_exam_node():
    args = parse_args(['2'])
    assert (args.count, args.threshold, args.delay, args.profile, args.seed, args.screen) == \
        (2, 1300.0, 5.0, '', 1, False)


def test_a_single_pair_is_a_fleet():
    assert parse_args(['1']).count == 1
    assert len(pair_arguments(1, 1300.0, 5.0)) == 1
    for count in ('0', '-3'):
        with pytest.raises(SystemExit):
            parse_args([count])
