"""The report's questions 4-9: each answer found by its question, then judged by the sheet's notes as
named checks against what the drone really prints. Pure, no I/O: pages in, proposals out.

Finding (:func:`find_answers`): a heading names its question (``4.``, ``4)``, ``Q4``, ``Q.4``,
``Question 4``, ``Exercice 4``, ``Réponse 4``; French and English), wherever the student put it:
answers out of order, two in one paragraph ("... /rosout. Q5: ..."), in a table's cells (read from
the page's ``layout`` text, the columns kept: then "to check", the reading order of a table is the
reader's guess). A passage runs from its heading to the next one. A question no heading names is
"no answer found": never a guess by position.

Judging (:func:`judge`): each question's notes are discrete checks with a name (``command``,
``nodes``, ``comment``...), each ok, not ok or None (cannot say), with the line it rests on. The
rule of the notes turns them into points. "Explained" / "a comment" is the one rule
:func:`own_sentences` applies: a sentence of the student's own (at least :data:`SENTENCE_WORDS`
words, not a command, not a line of output, not the sheet's question copied), in French or English.
Anything uncertain is "to check" with its reason: OCR words of low confidence in the passage, a
passage read from a table, an explanation that may be wrong. A proposal is never a point: the teacher
confirms it (review page, hand.csv).
"""
import re

from exam_lab.grader.score.reference import AVERAGE_RATE
from exam_lab.grader.score.report_tables import continued, table_rows
from exam_lab.grader.score.report_text import (SENTENCE_WORDS, commands_of, number, own_sentences, running_lines,
                                                stated_periods, stated_rates)
from exam_lab.grader.score.sheets import HAND_ITEMS

#: The report's questions the grader looks for.
QUESTIONS = ('Q4', 'Q5', 'Q6', 'Q7', 'Q8', 'Q9')
#: Proposal states (REPORT_CONTRACT.md).
PROPOSED, TO_CHECK, NO_ANSWER, NOT_READ = 'proposed', 'to check', 'no answer found', 'not read'
#: Longest passage kept in a proposal (the review page shows the page beside it).
MAX_PASSAGE = 4000

#: A heading that names its question by a word: anywhere on a line (two answers in one paragraph).
_NAMED = re.compile(r'(?<![\w/])(?:Q(?:uestions?)?|Exercice|Exercise|Ex|R[ée]ponse|Answer)\s*(?:n\s*[°o]\s*)?\.?\s*'
                    r'(\d{1,2})(?![\d.,]\d)(?:\s*[.):\-–]|\b)', re.I)
#: A heading of a number alone: at a line's start (``4.``, ``4)``, ``(4)``, ``4 -``, ``4:``, ``4/``,
#: ``4°)``, ``#4``; not a page's footer ``4 / 6``), or after a sentence's end within a line (``... rosout. 5) ...``).
_BARE = re.compile(r'(?:^|(?<=[.!?;]\s))[ \t>*•\-|]*(?:[(#]\s*)?(\d{1,2})\s*(?:°\s*)?(?:[.):\-–]|/(?!\s*\d))(?![\d.,]*\d)(?=\s|$)'
                   r'|^[ \t]*#\s*(\d{1,2})(?=\s)', re.M)
#: A line that is a page's number (a word processor's footer): "- 4 -", "4 / 6", "4 of 6", "Page 4".
_FOOTER = re.compile(r'^[ \t]*(?:(?:page|p\.)\s*\d{1,3}\b.*|[-–]\s*\d{1,3}\s*[-–]|\d{1,3}\s*(?:/|of|sur)\s*\d{1,3})[ \t]*$',
                     re.M | re.I)


def _headings(text):
    """``[(start, end, number, strong)]`` of the headings of a page's text (never a page's number)."""
    found = [(m.start(), m.end(), int(m.group(1)), True) for m in _NAMED.finditer(text) if _heads(text, m)]
    taken = [(s, e) for s, e, _, _ in found] + [m.span() for m in _FOOTER.finditer(text)]
    for m in _BARE.finditer(text):
        group = 1 if m.group(1) else 2
        if not any(s <= m.start(group) < e for s, e in taken):
            found.append((m.start(group), m.end(), int(m.group(group)), False))
    return sorted(found)


def _heads(text, match):
    """Whether a question named by a word heads an answer: at its line's start or after a sentence's
    end ("... rosout. Q5: ..."), or after a few words of a heading ("Réponse à la question 4", "Partie 1 -
    Question 4") when its punctuation, nothing or a new sentence follows; not a reference in a sentence
    ("As in question 4, the drone must run")."""
    before = text[text.rfind('\n', 0, match.start()) + 1:match.start()]
    if not before.strip() or re.search(r'[.!?;]\s*$', before):
        return True
    rest = text[match.end():].split('\n', 1)[0]
    return len(before) <= 40 and (match.group(0).rstrip()[-1] in '.):-\u2013' or not rest.strip() or
                                  rest.lstrip()[:1].isupper())


def _page_label(page, several_files, files):
    if several_files and files and 0 <= page.get('file', 0) < len(files):
        return '%s p.%d' % (files[page['file']].get('name', '?'), page.get('number', 0))
    return 'p.%d' % page.get('number', 0)


def find_answers(pages, files=()):
    """Each question of :data:`QUESTIONS` with its passage: ``{item: {"page", "label", "text", "how",
    "unsure", "doubts"}}`` (``how``: "heading" or "table"; ``unsure``: the page's low-confidence OCR
    words the passage holds; ``doubts``: why it is to check), or None when no heading names it.

    The pages (a ReportRecord's ``pages``, in order) are read as one text, so an answer may run onto
    the next page. Headings by a word (``Q5``) are trusted over bare numbers: when the report names
    at least two questions by a word, bare numbers are the answers' own lists (``1. Node [...]``).
    A bare number is a heading only the first time it appears, and 1-3 after a heading of 4-9 are
    the passage's own list too (the preparation questions come before). A question whose heading
    appears twice takes its first passage, and is to check."""
    several = len({p.get('file', 0) for p in pages}) > 1
    text, starts = '', []
    # a page's running header or footer is no sentence of an answer (a heading at two pages' tops stays)
    running = {line for line in running_lines([page.get('text') for page in pages]) if not _headings(line)}
    for page in pages:
        starts.append(len(text))
        lines = (page.get('text') or '').split('\n')
        text += '\n'.join('' if line.strip() in running else line for line in lines) + '\n\f\n'
    tables = [table_rows(page.get('layout') or '') for page in pages]
    for index in range(len(tables) - 1):  # a table's last row going on at the next page's top
        more = continued(pages[index + 1].get('layout') or '') if tables[index] else ''
        if more:
            number, passage = tables[index][-1]
            tables[index][-1] = (number, passage + '\n' + more)

    def in_table(start, number):  # a heading of a page's table: its text's order is not the table's
        index = max(i for i, s in enumerate(starts) if s <= start)
        return any(n == number for n, _ in tables[index])
    heads = [h for h in _headings(text) if not in_table(h[0], h[2])]
    strong = {n for _, _, n, s in heads if s and 4 <= n <= 9}
    if len(strong) >= 2:
        heads = [h for h in heads if h[3]]
    kept, seen, after_exploration = [], {}, False
    for head in heads:
        start, end, number, is_strong = head
        if not is_strong and (number in seen or (after_exploration and number <= 3)):
            continue
        seen[number] = seen.get(number, 0) + 1
        after_exploration = after_exploration or 4 <= number <= 9
        kept.append(head)
    found = {}
    for index, (start, end, number, _) in enumerate(kept):
        item = 'Q%d' % number
        if item not in QUESTIONS:
            continue
        stop = kept[index + 1][0] if index + 1 < len(kept) else len(text)
        page_index = max(i for i, s in enumerate(starts) if s <= start)
        passage = text[end:stop].replace('\f', '').strip()
        doubts = []
        if item in found:
            found[item]['doubts'].append('question %d has two headings in the report: the first is read' % number)
            continue
        found[item] = _passage(pages, page_index, starts, start, stop, passage, 'heading', doubts, several, files)
    # A table whose first column names the questions: each row read from its page's layout text.
    for page_index, rows in enumerate(tables):
        for number, passage in rows:
            item = 'Q%d' % number
            if item not in QUESTIONS or item in found:
                continue
            found[item] = _passage(pages, page_index, None, None, None, passage, 'table',
                                   ['read from a table (its rows and columns from the page\'s layout): which '
                                    'cell belongs to which question is to check'], several, files)
    return {item: found.get(item) for item in QUESTIONS}


def _passage(pages, page_index, starts, start, stop, passage, how, doubts, several, files):
    page = pages[page_index]
    covered = [pages[i] for i in range(len(pages)) if starts is None and i == page_index or
               starts is not None and starts[i] < stop and (i + 1 == len(starts) or starts[i + 1] > start)]
    unsure = sorted({w for p in covered for w in (p.get('unsure') or []) if w and w in passage})
    if unsure:
        doubts = doubts + ['OCR read %s with low confidence (page confidence %s)' % (
            ', '.join('"%s"' % w for w in unsure[:8]),
            '/'.join('%.0f' % p['confidence'] for p in covered if p.get('confidence') is not None) or '?')]
    return {'page': page.get('number'), 'label': _page_label(page, several, files), 'text': passage[:MAX_PASSAGE],
            'how': how, 'unsure': unsure, 'doubts': doubts, 'source': page.get('source')}


# --- the checks of each question --------------------------------------------------------------------

def named_check(name, ok, detail):
    """One named check of a proposal: ``ok`` True, False or None (cannot say), and what it rests on."""
    return {'name': name, 'ok': ok, 'detail': detail}


def _quote(text, limit=80):
    text = ' '.join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + '...'


def _names_in(text):
    return set(re.findall(r'(?<![\w/])(/[A-Za-z_][\w/]*)', text))


def _comment_check(passage, item, name='comment'):
    sentences = own_sentences(passage, item)
    if sentences:
        return named_check(name, True, '"%s"' % _quote(sentences[0])), sentences
    short = own_sentences(passage, item, 2)
    if short:  # "Deux nœuds tournent.": a comment, or a title? the teacher's call
        return named_check(name, None, 'only a sentence under %d words: "%s"' % (SENTENCE_WORDS, _quote(short[0]))), []
    return named_check(name, False, 'no sentence of the student\'s own (at least %d words beyond the commands, '
                               'their output and the question)' % SENTENCE_WORDS), sentences


def _command_check(passage, pattern, shown, squashed=None):
    """The ``command`` check: a command line of the passage matching ``pattern``; in a table's cell,
    where a narrow column wraps it ("rosnode" / "info" / "/mydro" / "ne"), the ``squashed`` pattern
    on the passage without its spaces."""
    for command in commands_of(passage):
        if re.match(pattern, command):
            return named_check('command', True, '`%s`' % _quote(command, 60))
    if squashed and re.search(squashed, re.sub(r'\s+', '', passage)):
        return named_check('command', True, '%s, its words wrapped in a table\'s cell' % shown)
    said = commands_of(passage)
    return named_check('command', False, 'no `%s`%s' % (shown, ' (commands: %s)' % ', '.join(
        '`%s`' % _quote(c, 40) for c in said[:3]) if said else ''))


def _q4(passage, ref, table=False):
    command = _command_check(passage, r'rosnode\s+list\b', 'rosnode list', table and 'rosnodelist')
    names = _names_in(passage)
    missing = [n for n in ref['nodes'] if n not in names]
    nodes = named_check('nodes', not missing, 'both nodes: %s' % ', '.join(ref['nodes']) if not missing
                   else 'missing %s (the drone shows %s)' % (', '.join(missing), ', '.join(ref['nodes'])))
    comment, _ = _comment_check(passage, 'Q4')
    if command['ok'] and nodes['ok']:
        points, doubts, rule = (1.0 if comment['ok'] else 0.5), [], 'command and both nodes: 1, half without a comment'
    else:
        points = 0.5 if command['ok'] or nodes['ok'] else 0.0
        doubts, rule = ['the command or its nodes are missing'], 'command and both nodes needed for the point'
    return [command, nodes, comment], points, doubts, rule


#: What question 5's notes single out, each with the words that explain it (French and English).
Q5_PARTS = (
    ('publications', r'publi'),
    ('subscriptions', r'subscri|abonn|souscri'),
    ('services', r'service'),
    ('contacting node', r'contacting|adress|address|\burl\b|\buri\b|xml-?rpc|\bport\b'),
    ('Pid', r'\bpid\b|process|processus'),
    ('direction', r'direction|outbound|inbound|sortant|entrant|\bsens\b|émet|envoi|send|sortie'),
    ('TCPROS', r'tcpros|\btcp\b|protocol'),
)


def _q5(passage, ref, table=False):
    node = re.escape(ref['node'])
    # the name as typed: "rosnode info mydrone" resolves to /mydrone as the global name does
    command = _command_check(passage, r'rosnode\s+info\s+/?%s(?![\w/])' % re.escape(ref['node'].lstrip('/')),
                             'rosnode info %s' % ref['node'], table and 'rosnodeinfo/?' + re.escape(ref['node'].lstrip('/')))
    names = _names_in(passage)
    missing = [t for t in ref['publications'] if t not in names]
    has_node = re.search(r'Node\s*\[\s*%s\s*\]' % node, passage) is not None
    output = named_check('output', has_node and not missing,
                    'Node [%s] and its publications %s' % (ref['node'], ', '.join(ref['publications']))
                    if has_node and not missing else 'missing: %s' % ', '.join(
                        (['Node [%s]' % ref['node']] if not has_node else []) + missing))
    # each line named in the student's words: a short sentence ("Pid : le processus.") counts, once
    # the answer has one sentence of its own at least
    prose = ' '.join(own_sentences(passage, 'Q5', 1)) if own_sentences(passage, 'Q5') else ''
    checks, unexplained = [command, output], []
    for part, words in Q5_PARTS:
        said = re.search(words, prose, re.I)
        checks.append(named_check('explains %s' % part, bool(said), 'explained' if said else 'not explained'))
        if not said:
            unexplained.append(part)
    doubts = []
    if re.search(r'(?:direction|outbound|connexion|connection)[^.]*(?:master|ma[iî]tre)', prose, re.I):
        doubts.append('says the connection goes to the master (it goes to the rosout node)')
    if not (command['ok'] and output['ok']):
        points = 1.0 if not unexplained else 0.5
        doubts.append('the command or its output is not the drone\'s')
        rule = 'rosnode info of the drone with each line explained: 2'
    elif not unexplained:
        points, rule = 2.0, 'every line explained: 2'
    else:
        points, rule = 1.0, 'lines not explained (%s): 1' % ', '.join(unexplained)
        if len(unexplained) < len(Q5_PARTS) - 2:
            doubts.append('most lines are explained: whether the rest is, is the teacher\'s call')
    return checks, points, doubts, rule


#: Words of an explanation of /rosout's role (a log), French and English.
ROSOUT_ROLE = r'\blog|journal|console|debug|erreur|error|warn|\binfo|centralis|agr[eé]g|aggreg|trace|stdout|' \
    r'standard output|sortie standard'
#: "Messages" alone: right when they are the nodes' log messages, which the sentence does not say.
ROSOUT_VAGUE = r'\bmessages?\b'
#: /rosout said to carry the nodes' exchanges with each other (it carries their logs to rosout).
ROSOUT_WRONG = r'between (?:the )?nodes|entre (?:les )?n(?:œ|oe|o)uds|entre eux|communiqu|communicat|[eé]chang'


def _q6(passage, ref, table=False):
    command = _command_check(passage, r'rostopic\s+list\b', 'rostopic list', table and 'rostopiclist')
    names = _names_in(passage)
    missing = [t for t in ref['topics'] if t not in names]
    topics = named_check('topics', not missing, ', '.join(ref['topics']) if not missing
                    else 'missing %s' % ', '.join(missing))
    about = [s for s in own_sentences(passage, 'Q6') if re.search(r'rosout', s, re.I)]
    if not about:  # "Ce topic sert à ..." right after /rosout is named: any own sentence then
        about = own_sentences(passage, 'Q6')
    role = [s for s in about if re.search(ROSOUT_ROLE, s, re.I)]
    vague = [s for s in about if re.search(ROSOUT_VAGUE, s, re.I)]
    wrong = [s for s in role or vague if re.search(ROSOUT_WRONG, s, re.I)]
    rosout = named_check('rosout role', bool(role), '"%s"' % _quote(role[0]) if role else
                    ('"%s": no word of logging in it' % _quote(about[0]) if about else '/rosout\'s role not explained'))
    doubts = []
    if wrong:
        doubts.append('"%s" says /rosout carries the nodes\' exchanges with each other (it carries their log '
                      'messages): may be a wrong explanation' % _quote(wrong[0]))
    if role:
        points, rule = 1.0, '/rosout explained: 1'
        if not (command['ok'] and topics['ok']):
            doubts.append('the command or the topics are missing')
    else:
        points, rule = 0.0, '/rosout not explained (or wrongly): 0'
        if vague and not wrong:
            doubts.append('"%s" says messages, not log messages: right if it means the nodes\' logs' % _quote(vague[0]))
        elif about and not wrong:
            doubts.append('an explanation of /rosout with no word of logging: may be right in other words')
    return [command, topics, rosout], points, doubts, rule


def _q7(passage, ref, table=False):
    command = _command_check(passage, r'(?:rostopic\s+(?:type|info)|rosmsg\s+(?:info|show))\b',
                             'rostopic type / rosmsg info', table and r'rostopic(?:type|info)|rosmsg(?:info|show)')
    kind = re.search(r'std_msgs/Float32', re.sub(r'\s+', '', passage), re.I)  # a table's cell may wrap it
    fields = re.search(r'float32\s+data', passage)
    # "the messages are Float32": the type named without its package, in the student's own words
    named = not (kind or fields) and any(re.search(r'(?<![\w/])float\s?32\b', sentence, re.I)
                                         for sentence in own_sentences(passage, 'Q7', 1))
    expected = ref['type'] or 'std_msgs/Float32'
    checks = [command,
              named_check('type', bool(kind or fields or named), '%s found' % (
                  'float32 data' if fields else expected if kind else 'Float32 (without std_msgs/)')
                  if kind or fields or named else 'neither %s nor float32 data' % expected),
              named_check('field', bool(fields), 'float32 data' if fields else 'the field float32 data not shown')]
    comment, _ = _comment_check(passage, 'Q7')
    checks.append(comment)
    doubts = ['the type named Float32 without its package (std_msgs/Float32)'] if named else []
    if not (kind or fields or named):
        return checks, 0.0, [], 'the type is missing: 0'
    if not fields:
        doubts.append('the type without its field (rosmsg info shows float32 data)')
    return checks, 1.0 if comment['ok'] else 0.5, doubts, 'the type: 1, half without a comment'


#: A stated rate within this share of the real one is right (the drone's own hz varies by a few %).
RATE_TOLERANCE = 0.1


def _close(value, target):
    return target is not None and target > 0 and abs(value - target) <= RATE_TOLERANCE * target


def _rounded_to(value, target):
    """True when ``target`` rounded to the decimals ``value`` is written with is ``value`` ("1 Hz" for
    0.778): a rate that may be the drone's, stated coarsely."""
    text = shown_number(value)
    decimals = len(text.split('.')[1]) if '.' in text else 0
    return target is not None and round(target, decimals) == value


def _q8(passage, ref, table=False):
    topic = ref['topic']
    bare = re.escape(topic.lstrip('/'))  # "rostopic echo temperature" resolves to /temperature
    command = _command_check(passage, r'rostopic\s+echo\b.*(?<![\w/])/?%s(?![\w/])' % bare, 'rostopic echo %s' % topic,
                             table and r'rostopicecho.*%s' % bare)
    values = re.findall(r'data\s*:\s*-?\d', passage)
    checks = [command, named_check('messages', bool(values), '%d message(s) pasted' % len(values) if values
                              else 'no message (data: ...) pasted')]
    real = ref['rate']
    # the student's own hz: on which topic, and what it measured
    # on which topic: a global name, or a relative one of the drone's ("rostopic hz temperature"); a
    # sentence naming the tool ("... with rostopic hz to measure it") names none
    known = {topic.lstrip('/'): topic, ref.get('other_topic', '').lstrip('/'): ref.get('other_topic')}
    hz_topics = [name if name.startswith('/') else known[name] for name in (
        m.group(1) for m in (re.match(r'rostopic\s+hz\s+(?:-\S+\s+(?:\d\S*\s+)?)*(\S+)', c)
                             for c in commands_of(passage)) if m)
        if name.startswith('/') or name in known and known[name]]
    measured = [number(r) for r in AVERAGE_RATE.findall(passage)]
    doubts = []
    if hz_topics and all(t != topic for t in hz_topics):
        doubts.append('rostopic hz was run on %s, not %s' % (', '.join(hz_topics), topic))
    sentences = own_sentences(passage, 'Q8', 1)  # "At 2 Hz." states a rate in three words
    stated = stated_rates(sentences)
    periods = [p for p in stated_periods(sentences) if 1.0 / p not in stated]
    # a rate pasted only as hz's output, with no sentence stating it, still answers "at which rate"
    candidates = stated or (measured[-1:] if measured and not doubts else [])
    right = [v for v in candidates if _close(v, real)]
    period = [v for v in candidates if real and _close(v, 1.0 / real)]
    as_period = [p for p in periods if _close(1.0 / p, real)]
    if right and not stated:
        doubts.append('the rate is only in the pasted hz output, no sentence states it')
    if right:
        rate = named_check('rate', True, '%s Hz %s (the drone: %s Hz, hz measured %s)' % (
            shown_number(right[0]), 'stated' if stated else 'from the pasted hz', shown_number(real), shown_number(ref['measured'])))
    elif as_period:
        rate = named_check('rate', True, 'one message every %s s stated, %s Hz (the drone: %s Hz)' % (
            shown_number(as_period[0]), shown_number(1.0 / as_period[0]), shown_number(real)))
        doubts.append('the rate is given as its period (%s s): whether that answers "at which rate" is the '
                      'teacher\'s call' % shown_number(as_period[0]))
    elif period:
        rate = named_check('rate', False, '%s is the period (s), not the rate: the drone publishes at %s Hz' % (
            shown_number(period[0]), shown_number(real)))
        doubts.append('a period given as a rate')
    elif candidates or periods:
        rate = named_check('rate', False, '%s stated, the drone publishes at %s Hz' % (
            ', '.join(['%s Hz' % shown_number(v) for v in candidates] +
                      ['one message every %s s' % shown_number(p) for p in periods]), shown_number(real)))
        other = ref.get('other_rate')
        if any(_close(v, other) for v in candidates) or any(_close(1.0 / p, other) for p in periods):
            doubts.append('the rate stated is %s\'s (%s Hz)' % (ref['other_topic'], shown_number(other)))
        if measured and any(_close(v, measured[-1]) for v in candidates) and not _close(measured[-1], real):
            doubts.append('the rate stated is the student\'s own hz output (%s Hz), not the drone\'s' % shown_number(measured[-1]))
        coarse = [v for v in candidates if _rounded_to(v, real)]
        if coarse:
            doubts.append('%s Hz is the drone\'s %s Hz rounded: right, stated coarsely?' % (
                shown_number(coarse[0]), shown_number(real)))
    else:
        rate = named_check('rate', False, 'no rate stated')
    checks.append(rate)
    if measured:
        checks.append(named_check('own hz', _close(measured[-1], real), 'pasted hz: %s Hz on %s' % (
            shown_number(measured[-1]), ', '.join(hz_topics) or '?')))
    if command['ok'] and rate['ok']:
        return checks, 1.0, doubts, 'echo and the rate: 1'
    if command['ok']:
        return checks, 0.5, doubts, 'command right, rate wrong or missing: 0.5'
    if rate['ok']:
        return checks, 0.5, doubts + ['the rate is right without `rostopic echo %s`' % topic], \
            'rate right without the command: 0.5'
    return checks, 0.0, doubts, 'neither the command nor the rate: 0'


def shown_number(value):
    """A number of points or Hz as the evidence writes it (``0.5``, ``2``, ``0.778``)."""
    return '?' if value is None else ('%.3f' % value).rstrip('0').rstrip('.')


def _q9(passage, ref, table=False):
    drone = ref['drone']
    # an OCR that lost the underscores ("catkin create pkg exam rospy std msgs"): read with them, said
    mended = re.sub(r'std[ ]msgs', 'std_msgs', re.sub(r'catkin[ _]?create[ _]?pkg', 'catkin_create_pkg', passage))
    doubts = ['read "catkin_create_pkg" and "std_msgs" where the text has spaces (an OCR drops underscores)'] \
        if mended != passage else []
    passage = mended
    made = [c for c in commands_of(passage) if c.startswith('catkin_create_pkg')]
    wanted = {'rospy', 'std_msgs', drone}
    good = [c for c in made if c.split()[1:2] == ['exam'] and set(c.split()[2:]) == wanted]
    squashed = re.sub(r'\s+', '', passage)
    if not good and table and 'catkin_create_pkgexam' in squashed and all(w in squashed for w in wanted):
        good = ['catkin_create_pkg exam rospy std_msgs %s (its words wrapped in a table\'s cell)' % drone]
    command = named_check('command', bool(good), '`%s`' % _quote(good[0], 60) if good else
                     ('`%s`: not exam with rospy, std_msgs, %s' % (_quote(made[0], 60), drone) if made
                      else 'no `catkin_create_pkg exam rospy std_msgs %s`' % drone))
    explained, _ = _comment_check(passage, 'Q9', 'explained')
    checks = [command, explained]
    if not explained['ok']:
        return checks, 0.0, doubts, 'nothing explained: 0'
    if command['ok']:
        return checks, 1.0, doubts, 'the command, explained: 1'
    return checks, 0.5 if made else 0.0, doubts + ['the command is not the sheet\'s'], 'the command is not the sheet\'s'


JUDGES = {'Q4': _q4, 'Q5': _q5, 'Q6': _q6, 'Q7': _q7, 'Q8': _q8, 'Q9': _q9}
#: The command each question asks for: a passage holding another question's and none of its own is
#: likely that question's answer (a report numbered its own way: "1." for the sheet's question 4).
SIGNATURES = {'Q4': r'rosnode\s+list', 'Q5': r'rosnode\s+info', 'Q6': r'rostopic\s+list',
              'Q7': r'rostopic\s+(?:type|info)|rosmsg\s+(?:info|show)', 'Q8': r'rostopic\s+(?:echo|hz)',
              'Q9': r'catkin_create_pkg'}


def _elsewhere(item, passage):
    """Why the passage of ``item`` may be another question's, or None."""
    said = commands_of(passage)
    if not said or any(re.match(SIGNATURES[item], c) for c in said):
        return None
    others = [other for other in QUESTIONS if other != item and any(re.match(SIGNATURES[other], c) for c in said)]
    return 'its commands are those of %s, not of %s: is the report numbered its own way?' % (
        ' and '.join(others), item) if others else None


def proposal(item, state, points, evidence, checks=(), page=None, passage=''):
    """One proposal as the contract has it (proposals.json's entry)."""
    return {'item': item, 'points': points, 'max': HAND_ITEMS[item][0], 'state': state,
            'evidence': ' '.join(evidence.split()), 'checks': list(checks), 'page': page, 'passage': passage}


def _summary(checks):
    return '; '.join('%s: %s (%s)' % (c['name'], {True: 'ok', False: 'no', None: '?'}[c['ok']], c['detail'])
                     for c in checks)


def judge(item, found, ref):
    """The proposal of ``item`` for its passage ``found`` (:func:`find_answers`' entry, or None) against
    the drone's reference facts ``ref`` (:func:`~exam_lab.grader.score.reference.facts`, or None when
    the drone could not be run: then every found answer is to check)."""
    if found is None:
        return proposal(item, NO_ANSWER, None, 'no heading names question %s in the report (looked for "%s.", '
                        '"%s)", "Q%s", "Question %s", "Exercice %s", also in tables): the teacher finds it or '
                        'gives 0' % ((item[1:],) * 6))
    where = '%s%s' % (found['label'], ' (table)' if found['how'] == 'table' else '')
    if ref is None:
        return proposal(item, TO_CHECK, None, '%s: the drone\'s reference outputs are missing, nothing was '
                        'compared' % where, page=found['page'], passage=found['text'])
    checks, points, doubts, rule = JUDGES[item](found['text'], ref, table=found['how'] == 'table')
    doubts = list(found['doubts']) + [why for why in [_elsewhere(item, found['text'])] if why] + list(doubts) + [
        'the %s check cannot say (%s): counted as not met' % (c['name'], c['detail']) for c in checks if c['ok'] is None]
    state = TO_CHECK if doubts else PROPOSED
    evidence = '%s: %s; rule %s: %s -> %s%s' % (where, _summary(checks), item, rule, shown_number(points),
                                               '; to check: %s' % '; '.join(doubts) if doubts else '')
    return proposal(item, state, points, evidence, checks, found['page'], found['text'])


def report_proposals(report, ref):
    """The six proposals of questions 4-9 for one student's report (a ReportRecord's value, or None:
    no report) against the reference facts ``ref``."""
    if report is None or report.get('state') != 'read':
        why = (report or {}).get('why') or 'no report read'
        return [proposal(item, NOT_READ, None, 'report not read: %s' % why) for item in QUESTIONS]
    found = find_answers(report.get('pages') or [], report.get('files') or [])
    return [judge(item, found[item], ref) for item in QUESTIONS]
