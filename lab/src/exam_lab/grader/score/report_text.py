"""What in a passage of a report is the student's own: the commands pasted, the tools' output, the
sentences of the student's (French or English), the sheet's question copied, the rates and periods
those sentences state. Pure, no rospy.

The one rule behind every "comment" and "explained" check of :mod:`exam_lab.grader.score.answers`
(:func:`own_sentences`).
"""
import re

#: A sentence of the student's own has at least this many words.
SENTENCE_WORDS = 4

#: Lines of the tools' own output: never a sentence of the student's.
_OUTPUT = re.compile(
    r'^\s*(?:/[\w/]+\s*(?:\[[\w/]+\])?\s*$|\*\s|data\s*:|-{3,}|average rate|min\s*:|subscribed to|no new messages'
    r'|Node \[|Publications\s*:|Subscriptions\s*:|Services\s*:|contacting node|Pid\s*:|Connections\s*:'
    r'|direction\s*:|transport\s*:|to\s*:\s*/|topic\s*:\s*/|float32 data\s*$|std_msgs/\w+\s*$|Created (?:file|folder)'
    r'|Successfully created|Type\s*:|Publishers\s*:|Subscribers\s*:|\[?(?:INFO|WARN|ERROR)\]?\s*\[)', re.I)
#: The tool's own part of an output line a student may explain on the line itself ("Pid: 13996 is the
#: process's number", "Subscriptions: None, it listens to nothing"): what follows it is the student's.
_OUTPUT_PART = re.compile(
    r'^\s*(?:[*\u2022-]\s*)?(?:Node\s*\[[^\]]*\]'
    r'|(?:Publications|Subscriptions|Services|Connections|Publishers|Subscribers)\s*:(?:\s*None\b)?'
    r'|contacting node\s+\S+(?:\s*\.\.\.)?|Pid\s*:\s*\d*'
    r'|direction\s*:\s*(?:outbound|inbound)?(?:\s*\([^)]*\))?(?:\s*\[\d+\])?'
    r'|transport\s*:\s*(?:TCPROS|UDPROS)?|Type\s*:\s*[\w/]*|data\s*:\s*[-+\d.eE]*|average rate\s*:\s*[\d.]*'
    r'|(?:to|topic)\s*:\s*/[\w/]*|/[\w/]+\s*(?:\[[\w/]+\]|\(\S+\))?)', re.I)
#: Words after an output line's own part that make the line the student's explanation of it.
_EXPLAINED_WORDS = 2
#: The report reader's lines around the OCR of a picture on a text page (ReportRecord's ``text``).
_PICTURE = re.compile(r'^\s*\[(?:picture \d+, OCR|end of picture \d+)\]\s*$')
#: A command line as pasted: a prompt, or a line that starts with one of the course's tools.
_PROMPT = re.compile(r'^\s*(?:[\w.-]+@[\w.-]+:[^$#]*[$#]|[$#>%])\s*')
_TOOLS = ('rosnode', 'rostopic', 'rosmsg', 'rossrv', 'rosservice', 'rosrun', 'roslaunch', 'roscore',
          'catkin_create_pkg', 'catkin_make', 'timeout', 'source', 'cd', 'ls')


def _first_word(line):
    words = line.split()
    return words[0] if words else ''


def running_lines(texts, edge=3):
    """The lines a word processor repeats at the top or the foot of the pages ``texts`` (a running
    header "ROS exam report, John Smith", a footer "Jane Doe - page 2"): among the first or last ``edge``
    lines of two pages or more, the same but for their numbers; never a command or a line of output."""
    seen = {}
    for text in texts:
        lines = [line.strip() for line in (text or '').splitlines() if line.strip()]
        for line in set(lines[:edge] + lines[-edge:]):
            if not is_command(line) and not _OUTPUT.match(line):
                seen.setdefault(re.sub(r'\d+', '#', line), set()).add(line)
    counts = {}
    for text in texts:
        lines = [line.strip() for line in (text or '').splitlines() if line.strip()]
        for key in {re.sub(r'\d+', '#', line) for line in lines[:edge] + lines[-edge:]}:
            counts[key] = counts.get(key, 0) + 1
    return {line for key, lines in seen.items() if counts.get(key, 0) >= 2 for line in lines}


def is_command(line):
    """Whether a line is a command as pasted (a prompt, or a line starting with a course's tool)."""
    return bool(_PROMPT.match(line)) or _first_word(line) in _TOOLS


def commands_of(text):
    """The command lines of a passage, their prompt left out (``rosnode list``)."""
    found = []
    for line in text.splitlines():
        stripped = _PROMPT.sub('', line, count=1).strip()
        for tool in ('rosnode', 'rostopic', 'rosmsg', 'catkin_create_pkg'):
            at = re.search(r'(?<![\w/])%s\b' % tool, stripped)
            if at:
                found.append(stripped[at.start():])
                break
    return found


#: Each question's statement as the sheets put it, word for word where both sheets agree (the copy
#: of a question in a report is not a sentence of the student's).
STATEMENTS = {
    'Q4': 'run the node from the package then list all the running nodes',
    'Q5': 'list the information about the node explain each line of the output you get',
    'Q6': 'list all the available topics explain the role of the rosout topic',
    'Q7': 'what kind of message is available on the topic',
    'Q8': 'display a few messages available on the topic at which rate are they published',
    'Q9': 'create a package exam in your catkin workspace with dependencies to rospy std_msgs and',
}


#: The names the sheets' statements use (``the node mydrone_node from the package mydrone``).
_SHEET_NAMES = ' mydrone submarinedrone submarine drone node temperature pressure robot remote'


def _words(text):
    return re.findall(r"[^\W\d_]+(?:'[^\W\d_]+)?", text.lower())


def _paragraphs(text):
    """The passage's runs of lines that are neither a command nor a line of output, each joined as
    one paragraph (a word processor wraps a sentence over lines)."""
    paragraphs, current = [], []
    for line in text.splitlines() + ['']:
        explains = _OUTPUT.match(line) and _explains_itself(line)
        if not line.strip() or is_command(line) or _OUTPUT.match(line) or _PICTURE.match(line):
            if current:
                paragraphs.append(' '.join(current))
            current = []
            if explains:  # "Pid: 13996 is the number of its process": a paragraph of its own
                paragraphs.append(line.strip().lstrip('*\u2022- '))
        else:
            current.append(line.strip())
    return paragraphs


def _explains_itself(line):
    """Whether an output line goes on with the student's words about it (at least
    :data:`_EXPLAINED_WORDS` words after the tool's own part)."""
    part = _OUTPUT_PART.match(line)
    return bool(part) and len(_words(line[part.end():])) >= _EXPLAINED_WORDS


def own_sentences(text, item, least=SENTENCE_WORDS):
    """The sentences of a passage that are the student's own: not a command, not a line of output, at
    least ``least`` words, not the sheet's statement of ``item`` copied (most of its words are the
    statement's or the sheet's names, and it holds no number). The rule behind every "comment" and
    "explained" check (``least`` 1: every word of the student's, for naming each line of an output)."""
    statement = set(_words(STATEMENTS.get(item, '') + _SHEET_NAMES)) if item in STATEMENTS else set()
    kept = []
    for paragraph in _paragraphs(text):
        for sentence in re.split(r'(?<=[.!?])\s+', paragraph):
            words = _words(sentence)
            if len(words) < least:
                continue
            if statement and not re.search(r'\d', sentence) and _copied(words, statement):
                continue
            kept.append(sentence.strip())
    return kept


def _copied(words, statement):
    """Whether a sentence of ``words`` is the statement copied: most of its words are the statement's
    (or the sheet's names), and it adds at most one word of its own, or covers most of the statement.
    An answer of the student's reuses the question's words ("Created the exam package with rospy and
    std_msgs as dependencies"), with words of its own around them."""
    inside = sum(w in statement for w in words)
    if inside < 0.7 * len(words):
        return False
    own = statement - set(_words(_SHEET_NAMES))  # the statement's words but the drones' names
    return len(words) - inside <= 1 or len(set(words) & own) >= 0.8 * len(own)


#: A rate stated in words: "0.77 Hz", "0,78Hz", "à 2 hertz", "2 messages par seconde", "rate of 0.78",
#: "a frequency of 0.78".
_RATE = re.compile(r'(\d+(?:[.,]\d+)?)\s*(?:hz|hertz|messages?\s*(?:par|per|/)\s*s(?:econde?)?|/\s*s\b|fois\s+par\s+seconde)',
                   re.I)
_RATE_WORD = re.compile(r'(?:rate|fr[ée]quen(?:ce|cy)|d[ée]bit|taux|rythme)\D{0,25}?(\d+(?:[.,]\d+)?)(?![\d.,]*\d)(?!\s*(?:s\b|sec))',
                        re.I)
#: A rate stated as its period: "every 1.3 seconds", "toutes les 1,29 s", "a period of 1.29 s", "1.3 s
#: between two messages".
_PERIOD = re.compile(r'(?:every|each|toutes\s+les|chaque|p[ée]riod[e]?\D{0,40}?)\s*(\d+(?:[.,]\d+)?)\s*'
                     r'(?:s\b|sec\b|secs\b|seconds?|secondes?)'
                     r'|(\d+(?:[.,]\d+)?)\s*(?:s|sec|seconds?|secondes?)\s+(?:between|entre)\b', re.I)


def number(text):
    """A number as a student writes it, a decimal comma too (``0,78``)."""
    return float(text.replace(',', '.'))


def stated_rates(sentences):
    """The rates a passage's own sentences state (Hz), in order."""
    found = []
    for sentence in sentences:
        for pattern in (_RATE, _RATE_WORD):
            for m in pattern.finditer(sentence):
                value = number(m.group(1))
                if value not in found:
                    found.append(value)
    return found


def stated_periods(sentences):
    """The periods (s) a passage's own sentences give for the rate ("every 1.3 seconds"), in order."""
    found = []
    for sentence in sentences:
        for m in _PERIOD.finditer(sentence):
            value = number(m.group(1) or m.group(2))
            if value > 0 and value not in found:
                found.append(value)
    return found
