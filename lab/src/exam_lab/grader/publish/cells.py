"""A CSV cell a spreadsheet cannot run, and read back as it was. No rospy here.

Every CSV the teacher opens in a spreadsheet (grades.csv, hand.csv, Moodle's worksheet filled) holds
text a student chose: a name, a folder, a group. A spreadsheet runs a cell that begins with ``=``,
``+``, ``-`` or ``@`` as a formula (``=HYPERLINK(...)``, ``-2+3``), and a tab or carriage return at
the start lets one slip past a check for those. OWASP's rule against CSV injection
(https://owasp.org/www-community/attacks/CSV_Injection): begin such a cell with a single quote, which
the spreadsheet shows as text.

So that the grader's own reading of its files gives back exactly what it wrote, a cell that already
begins with a single quote gets one too: :func:`read_cell` strips one leading quote, always. A name
really starting with a quote (``'t Hooft``) is written ``''t Hooft`` and read back ``'t Hooft``.
A lone ``-`` (Moodle's "no date") cannot be a formula and is left as it is.
"""

#: What a spreadsheet may run at the start of a cell (OWASP), and the quote that says "text".
FORMULA_STARTS = ('=', '+', '-', '@', '\t', '\r')
QUOTE = "'"


def needs_quote(value):
    """Whether ``value`` needs the quote to be a cell no spreadsheet runs (and reads back exactly)."""
    return value != '-' and value[:1] in FORMULA_STARTS + (QUOTE,)


def cell(value):
    """``value`` (any type: None is an empty cell) as a CSV cell that no spreadsheet runs."""
    text = '' if value is None else str(value)
    return QUOTE + text if needs_quote(text) else text


def read_cell(text):
    """The value :func:`cell` was given: one leading quote removed (only one)."""
    return text[1:] if text.startswith(QUOTE) else text


def row(values):
    """Each of ``values`` as a :func:`cell`."""
    return [cell(value) for value in values]
