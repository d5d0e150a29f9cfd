"""How the exam node judges a numeric parameter (``exam.node.read_number``), without a master.

The parameter server is replaced by a dict, so each rule runs in microseconds; bad_params.test checks
the same rules end to end (a logged fatal error and a non-zero exit).
"""
import pytest
import rospy

from exam import node

UNSET = object()


@pytest.fixture
def param(monkeypatch):
    """A function that sets (or, with UNSET, removes) the value of ``~delay`` the node will read."""
    def give(value):
        server = {} if value is UNSET else {'~delay': value}
        monkeypatch.setattr(node.rospy, 'get_param', lambda name, default=None: server.get(name, default))
    return give


def read_delay():
    return node.read_number('~delay', 5.0, lambda x: x >= 0.0, 'a number of seconds >= 0')


def test_an_unset_parameter_takes_its_default(param):
    param(UNSET)
    assert read_delay() == 5.0


@pytest.mark.parametrize('value, expected', [(2, 2.0), (0.0, 0.0), (2.5, 2.5), ('2.5', 2.5)])
def test_a_number_is_read_as_a_float(param, value, expected):
    param(value)
    number = read_delay()
    assert number == expected
    assert isinstance(number, float)


@pytest.mark.parametrize('value', [True, False, 'two', [2.0], None, float('nan'), float('inf'),
                                   -float('inf'), -0.5])
def test_an_unusable_value_is_an_error_naming_the_parameter_and_the_value(param, value):
    param(value)
    with pytest.raises(node.ParamError) as raised:
        read_delay()
    message = str(raised.value)
    assert rospy.resolve_name('~delay') in message
    assert repr(value) in message
    assert 'a number of seconds >= 0' in message


def test_the_default_itself_must_pass_the_check(param):
    # A default is a value like any other: an invalid one is reported, not returned.
    param(UNSET)
    with pytest.raises(node.ParamError):
        node.read_number('~rate', -1.0, lambda x: x > 0.0, 'a rate in Hz > 0')
    assert node.read_number('~rate', 10.0, lambda x: x > 0.0, 'a rate in Hz > 0') == 10.0
