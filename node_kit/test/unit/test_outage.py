"""A node's view of its master: what to do and log for each poll's answer (synthetic answers, no ROS)."""

from node_kit.outage import KNOWN, REREGISTER, UNKNOWN, UNREACHABLE, MasterWatch, classify

URI = 'http://ground:11311/'


def watch():
    return MasterWatch(URI, '/exam')


def test_a_master_that_knows_the_node_is_silent():
    w = watch()
    assert [w.observe(KNOWN, t) for t in (1.0, 2.0, 3.0)] == [(None, None, '')] * 3
    assert w.up


def test_an_outage_is_logged_once_then_its_end_once():
    w = watch()
    action, level, message = w.observe(UNREACHABLE, 10.0, 'ConnectionRefusedError: refused')
    assert (action, level) == (None, 'warn')
    assert message == ('master at http://ground:11311/ unreachable (ConnectionRefusedError: refused): '
                       '/exam keeps running; topics already connected keep flowing and the warning '
                       'service keeps its connection, but no new connection, parameter or name lookup '
                       'works until the master is back')
    assert not w.up
    # However long the outage, nothing more until it ends.
    assert [w.observe(UNREACHABLE, 10.0 + t, 'timeout') for t in range(1, 100)] == [(None, None, '')] * 99
    assert w.observe(KNOWN, 112.5) == (None, 'info', 'master at http://ground:11311/ reachable again '
                                       'after 102.5 s; it still knows /exam: nothing to re-register')
    assert w.up
    assert w.observe(KNOWN, 113.5) == (None, None, '')


def test_a_restarted_master_asks_for_re_registration_and_the_outage_is_measured():
    w = watch()
    w.observe(UNREACHABLE, 8.0, 'refused')
    w.observe(UNREACHABLE, 9.0, 'refused')
    assert w.observe(UNKNOWN, 11.0) == (REREGISTER, None, '')
    assert w.reregistered(11.2, 3, 3, 2, 3) == (
        None, 'info', 'master at http://ground:11311/ restarted after 3.2 s down, without /exam: '
                      're-registered 3 publications, 3 subscriptions, 2 services and 3 private parameters')
    assert w.up
    assert w.observe(KNOWN, 12.0) == (None, None, '')


def test_a_restart_between_two_polls_is_still_re_registered():
    w = watch()
    assert w.observe(UNKNOWN, 5.0) == (REREGISTER, None, '')
    assert w.reregistered(5.1, 5, 0, 3, 1)[2] == (
        'master at http://ground:11311/ restarted, without /exam: re-registered 5 publications, '
        '0 subscriptions, 3 services and 1 private parameters')


def test_a_failed_re_registration_is_logged_once_and_retried_every_poll():
    w = watch()
    assert w.observe(UNKNOWN, 5.0)[0] == REREGISTER
    assert w.reregister_failed(5.1, 'ConnectionResetError: reset') == (
        None, 'warn', 'could not re-register /exam with the master at http://ground:11311/ '
                      '(ConnectionResetError: reset): retrying every poll')
    assert not w.up
    assert w.observe(UNREACHABLE, 6.0, 'refused') == (None, None, '')  # the same outage
    assert w.observe(UNKNOWN, 7.0)[0] == REREGISTER
    assert w.reregister_failed(7.1, 'again') == (None, None, '')
    assert w.observe(UNKNOWN, 8.0)[0] == REREGISTER
    assert w.reregistered(8.1, 1, 1, 1, 0)[2].startswith(
        'master at http://ground:11311/ restarted after 3.0 s down, without /exam:')
    # A new outage is a new story: logged again, and so is its first failed re-registration.
    assert w.observe(UNREACHABLE, 20.0, 'refused')[1] == 'warn'
    assert w.observe(UNKNOWN, 21.0)[0] == REREGISTER
    assert w.reregister_failed(21.1, 'reset')[1] == 'warn'


def test_after_an_outage_that_needed_nothing_a_failed_re_registration_is_logged_again():
    w = watch()
    assert w.observe(UNKNOWN, 5.0)[0] == REREGISTER
    assert w.reregister_failed(5.1, 'reset')[1] == 'warn'
    assert w.observe(KNOWN, 6.0)[1] == 'info'  # the master came back knowing the node after all
    assert w.observe(UNKNOWN, 30.0)[0] == REREGISTER
    assert w.reregister_failed(30.1, 'reset')[1] == 'warn'


def test_a_master_that_knows_the_node_and_kept_its_pid_is_the_one_registered_with():
    assert classify(4242, 'http://vm:40001/', None) == KNOWN  # first poll: the pid is learnt
    assert classify(4242, 'http://vm:40001/', 4242) == KNOWN


def test_a_restarted_master_forgets_the_node():
    assert classify(5151, None, 4242) == UNKNOWN
    assert classify(5151, None, None) == UNKNOWN  # restarted before the first poll


def test_a_restarted_master_that_learnt_the_name_again_is_told_by_its_pid():
    # After a restart the node may be known to the new master through a parameter subscription or
    # a new publisher alone, with none of its other registrations: the pid differs.
    assert classify(5151, 'http://vm:40001/', 4242) == UNKNOWN


def test_a_master_whose_pid_cannot_be_read_is_not_trusted():
    assert classify(None, 'http://vm:40001/', 4242) == UNKNOWN


def test_status_up_down_and_re_registered():
    w = watch()
    assert w.status(5.0) == ('ok', 'master up, registered since the start', [
        ('master', URI), ('state', 'up'), ('down since [s]', 'up'), ('down for [s]', '0'),
        ('last answer at [s]', 'never'), ('re-registrations', '0'),
        ('last re-registration at [s]', 'never')])
    w.observe(KNOWN, 6.0)
    assert dict(w.status(7.0)[2])['last answer at [s]'] == '6.000'
    w.observe(UNREACHABLE, 10.0, 'refused')
    level, summary, values = w.status(12.5)
    assert (level, summary) == ('warn', 'master down for 2.5 s')
    assert dict(values)['down since [s]'] == '10.000' and dict(values)['state'] == 'down'
    assert dict(values)['down for [s]'] == '2.5'
    assert dict(values)['last answer at [s]'] == '6.000'
    w.reregister_failed(13.0, 'refused')
    assert w.status(13.0)[1] == 'master down for 3.0 s, re-registration failing'
    w.observe(UNKNOWN, 14.0)
    w.reregistered(14.25, 3, 4, 2, 5)
    level, summary, values = w.status(15.0)
    assert (level, summary) == ('ok', 'master up, re-registered 1 times, last at 14.250')
    assert dict(values)['last re-registration'] == ('3 publications, 4 subscriptions, 2 services, '
                                                    '5 private parameters')
    assert dict(values)['state'] == 'up' and dict(values)['re-registrations'] == '1'
    w.reregistered(20.0, 3, 4, 2, 5)
    assert w.status(21.0)[1] == 'master up, re-registered 2 times, last at 20.000'

