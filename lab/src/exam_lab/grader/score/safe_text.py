"""Student-derived text made safe to print or write for the teacher. Pure: no rospy, no I/O.

A student's node, launch file or file names put bytes into the records (evidence, the teacher's notes,
log tails, names); printed on a terminal, an escape sequence in them moves the cursor, erases the
screen or sets the title, so a traceback could rewrite the class summary ("17/17 graded") or hide the
"needs the teacher" block. :func:`clean` keeps printable text, newlines and tabs, and removes:

- every escape sequence whole: CSI (``ESC [`` ... final byte, and the 8-bit CSI U+009B), OSC
  (``ESC ]`` ... BEL or ST, 8-bit U+009D), the string sequences DCS/SOS/PM/APC, two-character ``ESC x``;
- every other control character: C0 but newline and tab, DEL, C1 (U+0080-U+009F);
- the bidirectional overrides, embeddings and isolates (U+202A-U+202E, U+2066-U+2069): they reorder
  what the teacher reads ("Trojan Source") without being seen.

A name in bytes that are not UTF-8 (a file name in a student's tar) reaches the records as Python's
surrogate escapes, kept exactly; shown, each such byte reads ``\\xNN`` (a lone surrogate of any other
kind ``\\udNNN``): no UTF-8 file, page or terminal can refuse it.

A carriage return that is not part of a CRLF becomes a newline: what it would have overwritten on a
terminal stays readable, on a line of its own. :func:`one_line` is for a cell (a name, a table cell):
line breaks and tabs become spaces too.
"""
import re

#: Escape sequences, whole: what follows ESC (or an 8-bit introducer) up to its end. An OSC or a
#: string sequence without its terminator ends at the line's end: its payload left after that is
#: plain text, shown rather than lost.
_SEQUENCE = re.compile(
    '(?:\x1b\\[|\x9b)[\x30-\x3f]*[\x20-\x2f]*[\x40-\x7e]?'         # CSI: parameters, intermediates, final
    '|(?:\x1b[\\]PX^_]|[\x9d\x90\x98\x9e\x9f])[^\x07\x1b\x9c\n]*(?:\x07|\x1b\\\\|\x9c)?'  # OSC, DCS, SOS, PM, APC
    '|\x1b[\x20-\x2f]*[\x30-\x7e]?')                                # ESC x (with intermediates: ESC ( B)
#: Control characters left once the sequences are gone (newline and tab are kept), and bidi controls.
_CONTROL = re.compile('[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]')
_LONE_CR = re.compile('\r\n?')
_SURROGATE = re.compile('[\ud800-\udfff]')
_BREAKS = re.compile('[\n\t]+')


def clean(text):
    """``text`` without escape sequences and control characters but newline and tab (see above)."""
    if not isinstance(text, str):
        text = str(text)
    return _CONTROL.sub('', _SEQUENCE.sub('', _LONE_CR.sub('\n', _SURROGATE.sub(_escaped, text))))


def _escaped(match):
    """A lone surrogate as text: the byte surrogateescape kept (``\\xff``), else its code point."""
    code = ord(match.group())
    return '\\x%02x' % (code - 0xdc00) if 0xdc80 <= code <= 0xdcff else '\\u%04x' % code


def one_line(text):
    """:func:`clean`, on one line: newlines and tabs become single spaces."""
    return _BREAKS.sub(' ', clean(text))


def cleaned(value):
    """A record (JSON-like: dicts, lists, tuples, strings, numbers) with every string in it, keys
    too, :func:`clean`; everything else as it was. A new value: ``value`` is not changed."""
    if isinstance(value, str):
        return clean(value)
    if isinstance(value, dict):
        return {cleaned(k): cleaned(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(cleaned(v) for v in value)
    return value
