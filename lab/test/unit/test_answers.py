"""The report's answers found by their question and judged by the sheet's notes (score/answers.py).

Every command output in these reports is the drone's own: the reference records in data/answers/ were
captured by exam_lab.grader.host.reference running mydrone and submarinedrone; a report here pastes
those outputs (as a student pastes their terminal) around sentences of a student's own.
"""
import json
import os
import re

import pytest

from exam_lab.grader.score import answers, code_items
from exam_lab.grader.score.reference import ReferenceRecord, facts

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'data', 'answers')


def reference(sheet):
    return ReferenceRecord.read(os.path.join(DATA, 'reference-%s.json' % sheet))


@pytest.fixture(scope='module')
def ref():
    return facts(reference('altitude'))


@pytest.fixture(scope='module')
def sub():
    return facts(reference('depth'))


def out(sheet, key):
    """``$ <line>`` and the output the drone printed for it, as pasted from a terminal."""
    command = reference(sheet).commands[key]
    return '$ %s\n%s' % (command.line, command.output)


def page(text, number=1, layout='', unsure=(), confidence=None, source='text'):
    return {'file': 0, 'number': number, 'source': source, 'text': text, 'layout': layout,
            'confidence': confidence, 'unsure': list(unsure), 'image': None}


def report(*pages):
    return {'version': 1, 'state': 'read', 'why': '', 'files': [{'name': 'report.pdf', 'kind': 'pdf',
                                                                 'converted': False, 'pages': len(pages), 'note': ''}],
            'pages': list(pages), 'notes': []}


def by_item(proposals):
    return {p['item']: p for p in proposals}


def check(proposal, name):
    (found,) = [c for c in proposal['checks'] if c['name'] == name]
    return found['ok']


# --- finding the passages ---------------------------------------------------------------------------

def english_report():
    return report(page('\n'.join([
        'ROS exam report',
        '4. Run the node mydrone_node from the package mydrone. Then list all the running nodes.',
        out('altitude', 'rosnode_list'),
        'Two nodes are running: the drone node and rosout, started by roscore with the master.',
        '5. List the information about the mydrone_node node.',
        out('altitude', 'rosnode_info'),
        'The node publishes the sensors and the log; it subscribes to no topic; its services are the warning '
        'and the logger ones. The contacting node line gives the address and port of the node. '
        'The Pid is the process identifier. The direction outbound means this node sends to rosout. '
        'The transport TCPROS is the protocol ROS uses over TCP.']), 1),
        page('\n'.join([
            '6. List all the available topics.',
            out('altitude', 'rostopic_list'),
            '/rosout is the topic where every node publishes its log messages, in one place.',
            '7. What kind of message is available on the /temperature topic?',
            out('altitude', 'rosmsg_info'),
            'The message holds one float value named data.',
            '8. Display a few messages.',
            out('altitude', 'rostopic_echo'),
            out('altitude', 'rostopic_hz'),
            'The temperature is published at about 0.78 Hz.',
            '9. Create a package exam',
            out('altitude', 'catkin_create_pkg'),
            'This creates the package exam with its package.xml and CMakeLists.txt listing the dependencies.']), 2))


def test_each_question_found_by_its_heading_english(ref):
    proposals = by_item(answers.report_proposals(english_report(), ref))
    assert [proposals[q]['state'] for q in answers.QUESTIONS] == ['proposed'] * 6
    assert [proposals[q]['points'] for q in answers.QUESTIONS] == [1.0, 2.0, 1.0, 1.0, 1.0, 1.0]
    assert proposals['Q4']['page'] == 1 and proposals['Q9']['page'] == 2
    assert 'rule Q4' in proposals['Q4']['evidence'] and '/mydrone' in proposals['Q4']['evidence']


def test_french_headings_out_of_order_and_two_in_one_paragraph(ref):
    text = '\n'.join([
        'Question 6 :',
        out('altitude', 'rostopic_list'),
        'Le topic /rosout sert à centraliser les messages de log de tous les nœuds.',
        'Question 4 :',
        out('altitude', 'rosnode_list'),
        'Deux nœuds tournent : le nœud du drone et rosout, lancé avec le master. Question 7 : le type est '
        'std_msgs/Float32, un seul champ float32 data qui porte la valeur du capteur.'])
    found = answers.find_answers([page(text)])
    assert '/rosout_agg' in found['Q6']['text'] and 'rosnode list' not in found['Q6']['text']
    assert 'rosnode list' in found['Q4']['text'] and 'float32' not in found['Q4']['text']
    assert found['Q7']['text'].startswith('le type est')
    proposals = by_item(answers.report_proposals(report(page(text)), ref))
    assert proposals['Q4']['points'] == 1.0 and proposals['Q6']['points'] == 1.0
    assert proposals['Q7']['points'] == 1.0 and proposals['Q7']['state'] == 'proposed'


def test_a_missing_question_is_no_answer_found_never_the_next_passage(ref):
    text = '\n'.join(['4)', out('altitude', 'rosnode_list'), 'Deux nœuds tournent, le drone et rosout.',
                      '6)', out('altitude', 'rostopic_list'), '/rosout est le topic des messages de log.'])
    proposals = by_item(answers.report_proposals(report(page(text)), ref))
    assert proposals['Q5']['state'] == 'no answer found' and proposals['Q5']['points'] is None
    assert proposals['Q8']['state'] == 'no answer found'
    assert proposals['Q4']['state'] == 'proposed' and proposals['Q6']['state'] == 'proposed'


def test_exercice_and_q_headings(ref):
    found = answers.find_answers([page('Exercice 4\n%s\nQ.5 -\nrien' % out('altitude', 'rosnode_list'))])
    assert '/mydrone' in found['Q4']['text'] and found['Q5']['text'] == 'rien'


def test_a_list_inside_an_answer_is_not_a_heading(ref):
    text = '\n'.join(['Q4', out('altitude', 'rosnode_list'), 'Two nodes run: the drone and rosout here.',
                      'Q5', out('altitude', 'rosnode_info'), '1. Node is the name of the node we asked about.',
                      '2. Publications are the topics the node publishes on.', 'Q6', 'x'])
    found = answers.find_answers([page(text)])
    assert 'Publications are the topics' in found['Q5']['text']


def pdf_pages(name):
    """The pages of a report of data/answers/ (made by LibreOffice headless: make_table_reports.py)
    as the report reader gives them: poppler's text in reading order and its -layout text."""
    import shutil
    import subprocess
    if shutil.which('pdftotext') is None:
        pytest.skip('poppler-utils (tools/install_deps.sh) is not installed')
    path = os.path.join(DATA, name + '.pdf')
    info = subprocess.run(['pdfinfo', path], stdout=subprocess.PIPE, check=True).stdout.decode()
    count = int(re.search(r'^Pages:\s+(\d+)', info, re.M).group(1))

    def text(number, *options):
        return subprocess.run(['pdftotext'] + list(options) + ['-f', str(number), '-l', str(number), path, '-'],
                              stdout=subprocess.PIPE, check=True).stdout.decode()
    return [page(text(n), n, layout=text(n, '-layout')) for n in range(1, count + 1)]


def test_a_table_with_cells_centred_on_their_row_french_out_of_order(ref):
    proposals = by_item(answers.report_proposals(report(*pdf_pages('table_middle')), ref))
    assert [proposals[q]['points'] for q in ('Q4', 'Q5', 'Q6', 'Q7', 'Q9')] == [1.0, 2.0, 1.0, 1.0, 1.0]
    assert all(proposals[q]['state'] == 'to check' and 'table' in proposals[q]['evidence']
               for q in ('Q4', 'Q5', 'Q6', 'Q7', 'Q9'))
    assert proposals['Q8']['state'] == 'no answer found'
    assert 'transport: TCPROS' in proposals['Q5']['passage'] and 'le protocole' in proposals['Q5']['passage']
    assert 'rosnode list' in proposals['Q4']['passage'] and 'rostopic' not in proposals['Q4']['passage']
    assert '/rosout_agg' in proposals['Q6']['passage'] and 'Deux' not in proposals['Q6']['passage']


def test_a_table_with_cells_on_their_rows_top_and_a_wrapped_command(sub):
    proposals = by_item(answers.report_proposals(report(*pdf_pages('table_top')), sub))
    assert {q: proposals[q]['points'] for q in ('Q4', 'Q7', 'Q8')} == {'Q4': 1.0, 'Q7': 1.0, 'Q8': 1.0}
    assert 'wrapped in a table' in proposals['Q8']['evidence']  # "rostopic echo -n" / "3" / "/pressure_robot"
    assert 'published at 2 Hz' in proposals['Q8']['passage']  # its row's last line, not a row of question 3
    assert [proposals[q]['state'] for q in ('Q6', 'Q9')] == ['no answer found'] * 2
    # question 5's cell split by its output's blank lines is still its row's, up to its last line
    assert 'transport: TCPROS' in proposals['Q5']['passage'] and 'Two nodes' not in proposals['Q5']['passage']
    assert proposals['Q5']['state'] == 'to check'


def test_a_heading_over_its_paragraph_is_no_table(ref):
    text = 'Question 4\n%s\nDeux nœuds tournent : le drone et rosout.\n\nQuestion 6\n%s\nLe topic /rosout reçoit les logs.' % (
        out('altitude', 'rosnode_list'), out('altitude', 'rostopic_list'))
    proposals = by_item(answers.report_proposals(report(page(text, layout=text)), ref))
    assert proposals['Q4']['state'] == 'proposed' and proposals['Q6']['state'] == 'proposed'


def test_each_line_named_in_a_wrapped_paragraph_of_short_sentences(ref):
    proposal = one('Q5', out('altitude', 'rosnode_info') + '\nNode [/mydrone] est le nom du nœud. Publications : les topics\n'
                   'publiés. Subscriptions : aucun abonnement. Services : les services offerts.\n« contacting node » '
                   'donne l\'adresse. Pid : le processus. Direction : sortante. Transport : TCPROS.', ref)
    assert proposal['points'] == 2.0


def test_a_low_confidence_ocr_word_in_the_passage_is_to_check(ref):
    text = 'Q4\n%s\nTwo nodes are running, the drone and rosout.' % out('altitude', 'rosnode_list')
    proposal = by_item(answers.report_proposals(report(page(text, unsure=['/mydrone'], confidence=71.0,
                                                                 source='ocr')), ref))['Q4']
    assert proposal['state'] == 'to check' and '"/mydrone"' in proposal['evidence']
    assert proposal['points'] == 1.0


def test_a_report_not_read_gives_not_read_for_each_question(ref):
    record = {'version': 1, 'state': 'not read', 'why': 'encrypted PDF', 'files': [], 'pages': [], 'notes': []}
    proposals = answers.report_proposals(record, ref)
    assert [p['state'] for p in proposals] == ['not read'] * 6
    assert all('encrypted PDF' in p['evidence'] for p in proposals)


# --- the named checks -------------------------------------------------------------------------------

def one(item, body, ref):
    return by_item(answers.report_proposals(report(page('%s.\n%s' % (item[1:], body))), ref))[item]


def test_q4_half_without_a_comment(ref):
    assert one('Q4', out('altitude', 'rosnode_list'), ref)['points'] == 0.5
    assert one('Q4', out('altitude', 'rosnode_list') + '\nThe drone and rosout are the two running nodes.',
               ref)['points'] == 1.0


def test_a_comment_under_four_words_is_to_check(ref):
    """"Deux nœuds tournent." may be the comment the notes ask for: counted as not met (0.5), to check,
    never 0.5 proposed as if there were none."""
    proposal = one('Q4', out('altitude', 'rosnode_list') + '\nDeux nœuds tournent.', ref)
    assert proposal['points'] == 0.5 and proposal['state'] == 'to check' and check(proposal, 'comment') is None
    assert 'Deux nœuds tournent' in proposal['evidence']
    assert one('Q4', out('altitude', 'rosnode_list'), ref)['state'] == 'proposed'


def test_q4_both_nodes_of_the_drone_needed(ref, sub):
    proposal = one('Q4', out('altitude', 'rosnode_list') + '\nThe drone and rosout are the two running nodes.', sub)
    assert check(proposal, 'nodes') is False and proposal['state'] == 'to check'
    assert '/submarine_drone' in proposal['evidence']


def test_q5_lines_not_explained_is_1(ref):
    proposal = one('Q5', out('altitude', 'rosnode_info') + '\nThe node publishes the sensors and its services '
                   'are listed there.', ref)
    assert proposal['points'] == 1.0
    assert check(proposal, 'explains Pid') is False and check(proposal, 'explains TCPROS') is False


def test_q5_each_singled_out_line_explained_is_2_in_french(ref):
    proposal = one('Q5', out('altitude', 'rosnode_info') + '\nLe nœud publie les capteurs et rosout, il ne '
                   's\'abonne à aucun topic, ses services sont listés. La ligne contacting node donne l\'adresse '
                   'et le port du nœud. Le Pid est le numéro du processus. La direction outbound veut dire que le '
                   'nœud envoie vers rosout. Le transport TCPROS est le protocole de ROS.', ref)
    assert proposal['points'] == 2.0 and proposal['state'] == 'proposed'


def test_q5_each_line_explained_on_the_line_itself(ref):
    """"Pid: 13996 is the id of its process": the output's line, then the student's words about it, is
    an explanation; the output alone is not (the drone's own lines stay output, a host name in them too)."""
    info = out('altitude', 'rosnode_info')
    explained = '\n'.join(['Explanation of each line:', 'Node [/mydrone]: the name of the node we asked about.',
                           'Publications: the topics the node publishes on.',
                           'Subscriptions: None, the node listens to no topic.',
                           'Services: the services the node offers.',
                           'contacting node http://127.0.0.1:40391/: the address and port of the node.',
                           'Pid: 13996 is the id of the process of the node.',
                           'direction: outbound, the node sends the messages.',
                           'transport: TCPROS, the protocol used by ROS over TCP.'])
    proposal = one('Q5', info + '\n' + explained, ref)
    assert proposal['points'] == 2.0, proposal['evidence']
    proposal = one('Q5', info + '\nPid: 13996\nSubscriptions: None\n * /mydrone (http://vm-student:40000/)', ref)
    assert proposal['points'] == 1.0 and check(proposal, 'explains Pid') is False


def test_q5_a_connection_said_to_go_to_the_master_is_to_check(ref):
    proposal = one('Q5', out('altitude', 'rosnode_info') + '\nThe node publishes topics, subscribes to none, '
                   'offers services. Contacting node gives its address. The Pid is its process number. '
                   'The direction outbound goes to the master. TCPROS is the protocol.', ref)
    assert proposal['state'] == 'to check' and 'master' in proposal['evidence']


def test_q6_rosout_role_missing_is_0(ref):
    assert one('Q6', out('altitude', 'rostopic_list'), ref)['points'] == 0.0
    assert one('Q6', out('altitude', 'rostopic_list') + '\n/rosout carries the log messages of every node.',
               ref)['points'] == 1.0


def test_q6_a_rosout_explanation_without_logging_is_0_to_check(ref):
    proposal = one('Q6', out('altitude', 'rostopic_list') + '\n/rosout is the topic that gives the altitude.', ref)
    assert proposal['points'] == 0.0 and proposal['state'] == 'to check'


@pytest.mark.parametrize('sentence, points, state', [
    ('rosout is used to send messages between nodes.', 0.0, 'to check'),
    ('/rosout permet aux nœuds de communiquer entre eux avec des messages.', 0.0, 'to check'),
    ('/rosout est le topic où les nœuds publient leurs messages.', 0.0, 'to check'),
    ('/rosout: standard output of the nodes, like stdout.', 1.0, 'proposed'),
    ('The /rosout topic collects the logs (rospy.loginfo) of all nodes.', 1.0, 'proposed'),
])
def test_q6_messages_alone_or_between_nodes_is_no_logging_role(ref, sentence, points, state):
    """/rosout carries the nodes' log messages: "messages between nodes" is the wrong role, "messages"
    alone may be either; both to check, never 1 proposed."""
    proposal = one('Q6', out('altitude', 'rostopic_list') + '\n' + sentence, ref)
    assert (proposal['points'], proposal['state']) == (points, state), proposal['evidence']


def test_q7_the_type_half_without_a_comment(ref):
    assert one('Q7', out('altitude', 'rosmsg_info'), ref)['points'] == 0.5
    assert one('Q7', out('altitude', 'rosmsg_info') + '\nThe message holds a single float named data.',
               ref)['points'] == 1.0
    assert one('Q7', 'The message holds a single number of the sensor.', ref)['points'] == 0.0


@pytest.mark.parametrize('sentence', ['The messages are Float32.', 'Le type de message est un Float32 (std_msgs).'])
def test_q7_the_type_named_without_its_package_is_to_check(ref, sentence):
    """"The messages are Float32" names the type: never 0 proposed as "the type is missing"."""
    proposal = one('Q7', sentence, ref)
    assert check(proposal, 'type') is True and proposal['points'] == 1.0 and proposal['state'] == 'to check'
    assert one('Q7', 'The messages are Float64 numbers.', ref)['points'] == 0.0


def test_q8_rate_wrong_with_the_right_command_is_half(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nThe messages are published at 10 Hz.', ref)
    assert proposal['points'] == 0.5 and check(proposal, 'rate') is False


def test_q8_the_stated_rate_compared_with_the_drone(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\n' + out('altitude', 'rostopic_hz') +
                   '\nLa température est publiée à 0,78 Hz environ.', ref)
    assert proposal['points'] == 1.0 and proposal['state'] == 'proposed'


def test_q8_a_period_given_as_a_rate_is_said(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nThe rate is 1.28 Hz.', ref)
    assert proposal['points'] == 0.5 and 'period' in proposal['evidence'] and proposal['state'] == 'to check'


@pytest.mark.parametrize('sentence', [
    'A new temperature message arrives every 1.3 seconds or so.',
    'Les messages arrivent toutes les 1,29 s environ.',
    'The period between two messages is about 1.29 s.',
])
def test_q8_the_rate_given_as_its_period_in_seconds_is_right_and_to_check(ref, sentence):
    """"Every 1.3 s" answers "at which rate" with the drone's period: the rate check holds (1/1.3 Hz is
    the drone's), said to check; never "no rate stated" and 0.5 proposed as if it were wrong."""
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\n' + sentence, ref)
    assert check(proposal, 'rate') is True and proposal['points'] == 1.0
    assert proposal['state'] == 'to check' and 'given as its period' in proposal['evidence']


def test_q8_a_period_of_the_other_topic_is_wrong_and_said(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nOne message every 0.5 s.', ref)
    assert check(proposal, 'rate') is False and proposal['points'] == 0.5
    assert "/pressure's" in proposal['evidence'] and proposal['state'] == 'to check'


def test_q8_a_rate_stated_in_a_short_sentence(sub):
    """"Published at 2 Hz." is three words: too short for a comment, but it states the rate."""
    proposal = one('Q8', out('depth', 'rostopic_echo') + '\nPublished at 2 Hz.', sub)
    assert check(proposal, 'rate') is True and proposal['points'] == 1.0


def test_the_node_and_topic_named_relative_as_rosnode_and_rostopic_resolve_them(ref):
    """`rosnode info mydrone` and `rostopic echo temperature` are the drone's /mydrone and /temperature
    (a relative name resolves in the root namespace); `rostopic hz pressure` is hz of /pressure."""
    info = out('altitude', 'rosnode_info').split('\n', 1)[1]
    assert check(one('Q5', 'rosnode info mydrone\n' + info, ref), 'command') is True
    assert check(one('Q5', 'rosnode info mydrone_node\n' + info, ref), 'command') is False
    echo = out('altitude', 'rostopic_echo').split('\n', 1)[1]
    proposal = one('Q8', 'rostopic echo temperature\n' + echo + '\nrostopic hz pressure\nThey come at 0.78 Hz.', ref)
    assert check(proposal, 'command') is True and 'hz was run on /pressure' in proposal['evidence']
    assert check(one('Q8', 'rostopic echo temperatures\n' + echo, ref), 'command') is False


def test_q8_a_frequency_without_its_unit_in_english(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nMessages are published at a frequency of 0.78.', ref)
    assert check(proposal, 'rate') is True and proposal['points'] == 1.0


def test_q8_the_drones_rate_rounded_coarsely_is_to_check(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nIt publishes at 1 Hz approximately.', ref)
    assert proposal['points'] == 0.5 and proposal['state'] == 'to check' and 'rounded' in proposal['evidence']


def test_q8_rostopic_hz_named_in_a_sentence_is_no_topic(ref):
    """A sentence that names the tool ("... according to rostopic hz.") is not a command run on "hz."."""
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\nPublished at 0.777 Hz on average according to '
                   'rostopic hz.', ref)
    assert proposal['state'] == 'proposed' and proposal['points'] == 1.0 and 'hz was run on' not in proposal['evidence']


def test_q8_hz_run_on_another_topic_is_said(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\n' + out('altitude', 'rostopic_hz_other') +
                   '\nThey are published at 2 Hz.', ref)
    assert proposal['points'] == 0.5 and 'hz was run on /pressure' in proposal['evidence']
    assert "/pressure's" in proposal['evidence']


def test_q8_submarine_rate(sub):
    proposal = one('Q8', out('depth', 'rostopic_echo') + '\nOn reçoit 2 messages par seconde.', sub)
    assert proposal['points'] == 1.0


def test_q9_nothing_explained_is_0(ref):
    assert one('Q9', out('altitude', 'catkin_create_pkg'), ref)['points'] == 0.0
    assert one('Q9', out('altitude', 'catkin_create_pkg') + '\nLa commande crée le paquet exam avec ses '
               'dépendances.', ref)['points'] == 1.0


def test_q9_the_drone_of_the_sheet(sub):
    proposal = one('Q9', out('altitude', 'catkin_create_pkg') + '\nThe command makes the exam package with its '
                   'dependencies.', sub)
    assert check(proposal, 'command') is False and proposal['points'] == 0.5


def test_a_copied_question_is_not_a_comment(ref):
    body = 'Run the node mydrone_node from the package mydrone. Then list all the running nodes.\n' + \
        out('altitude', 'rosnode_list')
    assert one('Q4', body, ref)['points'] == 0.5


def test_an_answer_reusing_the_questions_words_is_the_students_own(ref):
    """An explanation made of the statement's words with words of its own ("Created the exam package
    with rospy and std_msgs as dependencies") explains; the statement copied, in whole or in part, does not."""
    made = 'catkin_create_pkg exam rospy std_msgs\n'
    for own in ('Created the exam package with rospy and std_msgs as dependencies.',
                'Created the exam package with rospy, std_msgs and mydrone as dependencies.'):
        assert check(one('Q9', made + own, ref), 'explained') is True, own
    for copied in ('Create a package exam in your catkin workspace, with dependencies to rospy, std_msgs and mydrone;',
                   'Create a package exam.',
                   'Question: create a package exam in your catkin workspace, with dependencies to rospy, std_msgs '
                   'and mydrone.'):
        assert check(one('Q9', made + copied, ref), 'explained') is False, copied


@pytest.mark.parametrize('head', ['(4)', '4/', '4°)', '#4', '4 -', 'Question n° 4 :', 'Questions 4 et 5 :'])
def test_more_headings_of_a_number(ref, head):
    found = answers.find_answers([page('Name: Jane Doe, group 3\n\n%s\n%s\nTwo nodes run here.\n9. nothing'
                                       % (head, out('altitude', 'rosnode_list')))])
    assert '/mydrone' in found['Q4']['text'] and found['Q9']['text'] == 'nothing'


def test_a_page_footer_is_no_heading(ref):
    """A word processor's page number ("4 / 6", "4/6", "- 4 -", "4 of 6", "Page 4") at a page's foot is
    not question 4."""
    for footer in ('4 / 6', '4/6', '- 4 -', '4 of 6', '4 sur 6', 'Page 4', 'page 4 / 6'):
        found = answers.find_answers([page('Q5\nrien\n\n%s' % footer, 4)])
        assert found['Q4'] is None and found['Q5']['text'].startswith('rien'), footer


def test_a_report_numbered_its_own_way_is_to_check(ref):
    """A report that numbers its answers 1 to 6 (the preparation left out): its "4." holds question 7's
    command, said and to check, never judged silently as question 4's."""
    text = '\n'.join(['1. rosnode list', '/mydrone', '/rosout', 'Two nodes run: the drone and rosout.',
                      '4. rosmsg show std_msgs/Float32', 'float32 data', 'A single float field named data.',
                      '5. rostopic echo /temperature', 'data: 2.8', '---', 'They come at 0.78 Hz here.',
                      '6. catkin_create_pkg exam rospy std_msgs mydrone', 'This makes the exam package.'])
    proposals = by_item(answers.report_proposals(report(page(text)), ref))
    for item, other in (('Q4', 'Q7'), ('Q5', 'Q8'), ('Q6', 'Q9')):
        assert proposals[item]['state'] == 'to check', proposals[item]
        assert 'commands are those of %s, not of %s' % (other, item) in proposals[item]['evidence']
    assert 'numbered its own way' not in by_item(answers.report_proposals(english_report(), ref))['Q8']['evidence']


def test_a_question_named_in_a_sentence_is_no_heading(ref):
    """"As in question 4, the drone must run first." refers to question 4 inside question 8's answer:
    the passage goes on (its rate is read), and question 4 has one heading."""
    text = '\n'.join(['Question 4', out('altitude', 'rosnode_list'), 'Two nodes run: the drone and rosout.',
                      'Question 8', out('altitude', 'rostopic_echo'),
                      'As in question 4, the drone must run first. The messages come at 0.78 Hz.'])
    proposals = by_item(answers.report_proposals(report(page(text)), ref))
    assert proposals['Q8']['points'] == 1.0 and proposals['Q8']['state'] == 'proposed', proposals['Q8']['evidence']
    assert proposals['Q4']['state'] == 'proposed', proposals['Q4']['evidence']
    for head in ('Réponse à la question 4', 'Partie 1 - Question 4', 'Answer to question 4:'):
        assert answers.find_answers([page('%s\n%s' % (head, out('altitude', 'rosnode_list')))])['Q4'], head


def test_a_running_header_or_footer_is_no_comment(ref):
    """A word processor's header ("ROS exam report, John Smith") and footer ("John Smith - page 2") on
    every page fall inside an answer that runs onto the next page: never its comment. The headings at
    two pages' tops, commands and output stay."""
    head, foot = 'ROS exam report, John Smith', 'John Smith - page %d'
    pages = [page('\n'.join([head, 'Question 4', '$ rosnode list', foot % 1]), 1),
             page('\n'.join([head, '/mydrone', '/rosout', 'Question 5', 'rien', foot % 2]), 2),
             page('\n'.join([head, 'Question 6', '$ rostopic list', foot % 3]), 3)]
    proposals = by_item(answers.report_proposals(report(*pages), ref))
    assert proposals['Q4']['points'] == 0.5 and check(proposals['Q4'], 'comment') is False, proposals['Q4']['evidence']
    assert check(proposals['Q6'], 'command') is True and proposals['Q5']['passage'] == 'rien'


def test_without_the_reference_every_answer_is_to_check():
    proposals = answers.report_proposals(english_report(), None)
    assert [p['state'] for p in proposals] == ['to check'] * 6 and all(p['points'] is None for p in proposals)


# --- comments and quality ---------------------------------------------------------------------------

def units(commented, total):
    return [{'file': 'scripts/exam_node.py', 'line': n + 1, 'kind': 'function' if n % 2 else 'if', 'name': 'f%d' % n,
             'commented': n < commented} for n in range(total)]


@pytest.mark.parametrize('commented, points', [(10, 4.0), (8, 4.0), (5, 2.0), (3, 0.0)])
def test_comments_mapped_onto_the_notes(commented, points):
    proposal = code_items.comments_proposal({'comments': 10, 'code': 50, 'files': ['scripts/exam_node.py'],
                                          'units': units(commented, 10), 'quality': []})
    assert proposal['points'] == points and proposal['state'] == 'to check'
    assert '%d of 10 functions and blocks' % commented in proposal['evidence']
    if commented < 10:
        assert 'scripts/exam_node.py:%d' % (commented + 1) in proposal['evidence']


def test_quality_signals_cost_points_with_file_and_line():
    signals = [{'file': 'scripts/exam_node.py', 'line': 40, 'kind': 'service in a loop', 'detail': 'warn() each pass'},
               {'file': 'scripts/exam_node.py', 'line': 3, 'kind': 'pyflakes', 'detail': "'os' imported but unused"}]
    proposal = code_items.quality_proposal({'comments': 1, 'code': 1, 'files': [], 'units': [], 'quality': signals})
    assert proposal['points'] == 0.5 and proposal['state'] == 'to check'
    assert 'scripts/exam_node.py:40 service in a loop' in proposal['evidence']
    clean = code_items.quality_proposal({'comments': 1, 'code': 1, 'files': [], 'units': [], 'quality': []})
    assert clean['points'] == 2.0 and clean['state'] == 'to check'


def test_eight_proposals_per_student_in_order(ref):
    proposals = code_items.student_proposals(english_report(), ref, None)
    assert [p['item'] for p in proposals] == list(answers.QUESTIONS) + ['comments', 'quality']
    assert [p['max'] for p in proposals] == [1.0, 2.0, 1.0, 1.0, 1.0, 1.0, 4.0, 2.0]
    json.dumps(proposals)


def test_a_numbered_list_inside_an_answer_under_bare_number_headings(ref):
    text = '\n'.join(['4.', out('altitude', 'rosnode_list'), 'Two nodes run: the drone and rosout here.',
                      '5.', out('altitude', 'rosnode_info'), '1. Node is the name of the node we asked about.',
                      '2. Publications are the topics the node publishes on.',
                      '4. Services are what the node offers to call.', '6.', 'x'])
    found = answers.find_answers([page(text)])
    assert 'Publications are the topics' in found['Q5']['text'] and 'Services are what' in found['Q5']['text']
    assert found['Q4']['text'].endswith('rosout here.') and found['Q6']['text'] == 'x'


def test_q7_the_type_without_its_field_is_to_check(ref):
    proposal = one('Q7', out('altitude', 'rostopic_type') + '\nThe topic carries a standard float message.', ref)
    assert proposal['points'] == 1.0 and proposal['state'] == 'to check' and check(proposal, 'field') is False


def test_a_sentence_wrapped_over_lines_is_one_sentence(ref):
    assert one('Q4', out('altitude', 'rosnode_list') + '\nDeux nœuds tournent\navec le master.', ref)['points'] == 1.0


def test_q8_a_rate_only_pasted_is_to_check(ref):
    proposal = one('Q8', out('altitude', 'rostopic_echo') + '\n' + out('altitude', 'rostopic_hz'), ref)
    assert proposal['points'] == 1.0 and proposal['state'] == 'to check' and 'no sentence states it' in proposal['evidence']


def test_q9_underscores_an_ocr_dropped_are_read_and_said(ref):
    # tesseract's reading of a scanned report's line (lab/test/unit/data/reports/scan.pdf, reader47's fixture)
    proposal = one('Q9', '$ catkin create pkg exam rospy std_msgs mydrone\nLa commande crée le paquet exam avec ses '
                   'dépendances.', ref)
    assert proposal['points'] == 1.0 and proposal['state'] == 'to check' and 'underscores' in proposal['evidence']


def test_the_readers_picture_lines_are_not_a_sentence(ref):
    # the report reader puts a text page's screenshot, read by OCR, between these lines (ReportRecord)
    body = '[picture 1, OCR]\n%s\n[end of picture 1]\nLes deux nœuds tournent.' % out('altitude', 'rostopic_type')
    proposal = one('Q7', body, ref)
    assert proposal['checks'][-1]['detail'] == '"Les deux nœuds tournent."'
