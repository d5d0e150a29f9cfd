"""Unit tests of the fleet launcher's pure part (no master): namespaces, seeds, argument parsing."""
import pytest

from exam_lab.fleet import pair_arguments, parse_args


def test_each_pair_gets_its_own_namespace_and_seed():
    fleet = pair_arguments(3, 1500.0, 2.0, profile='', seed=7)
    assert len(fleet) == 3
    assert [args[0] for args in fleet] == ['ns:=drone1', 'ns:=drone2', 'ns:=drone3']
    assert [args[-1] for args in fleet] == ['seed:=7', 'seed:=8', 'seed:=9']
    for args in fleet:
        assert 'threshold:=1500.0' in args
        assert 'delay:=2.0' in args


def test_no_seed_leaves_the_simulator_default():
    fleet = pair_arguments(2, 1300, 5, seed=None)
    assert not any(arg.startswith('seed:=') for args in fleet for arg in args)


def test_profile_and_output_are_passed_through():
    (args,) = pair_arguments(1, 1300, 5, profile='[[0, 1000], [10, 1500]]', output='screen')
    assert 'profile:=[[0, 1000], [10, 1500]]' in args
    assert 'output:=screen' in args


def test_an_empty_fleet_is_refused():
    with pytest.raises(ValueError):
        pair_arguments(0, 1300, 5)


def test_command_line():
    args = parse_args(['4', '--threshold', '1400', '--delay', '3', '--seed', '11'])
    assert (args.count, args.threshold, args.delay, args.seed) == (4, 1400.0, 3.0, 11)
    with pytest.raises(SystemExit):
        parse_args(['0'])
