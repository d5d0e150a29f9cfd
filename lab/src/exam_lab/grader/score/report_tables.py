"""A report's table whose first column names the questions, read from a page's ``pdftotext -layout``
text: each question's row, each row's cells. Pure, no rospy.

A word processor's table comes out of a PDF's text layer column by column (every question number,
then every command, then every output), so the page's reading-order text cannot say which cell
belongs to which question. Its layout text keeps the columns where they stand: a question's number
at the start of a line, its cells to the right. A row's lines are the blocks (between blank lines)
that hold its number, or that lie nearest to it (cells centred on their row) or below it (cells on
their row's top: the table's own alignment, read from its first row). Columns start where cells
start (:func:`_columns`); a word belongs to the column it starts in. A cell of prose (its wrapped lines) is read as one paragraph; a cell of output keeps its lines.
What this rests on is a reading of the page, never certain: :mod:`~exam_lab.grader.score.answers`
makes every answer read from a table "to check".
"""
import re

#: A question's number at a line's start, a cell's gap (two spaces or more) after it.
_CELL = re.compile(r'^[ \t|]*(?:Q(?:uestion)?\s*)?(\d{1,2})[.)]?(?= {2,}|\t|\s*$)', re.I)
#: A table's header row: a cell "Question" (or "Q", "N°", "#") and another cell after it.
_HEADER = re.compile(r'^\s*(?:Questions?|Q\.?|N°|No\.?|#|Exercices?)\s+(?![\d.)])\S', re.I)
#: Characters a cell's text may shift from row to row and still be its column's.
SHIFT = 6
#: The least a table must name: two of the report's questions.
MIN_ROWS = 2


def _columns(lines):
    """``[(start, end)]`` of the columns of ``lines``: where cells start (a word at a line's start or
    after two spaces or more) on at least two lines, starts a few characters apart being one column's
    (a word processor shifts a cell's text a little from row to row); each column ends where the
    next starts."""
    starts = {}
    for line in lines:
        for m in re.finditer(r'(?:^|(?<=\s\s))(\S)', line):
            starts[m.start(1)] = starts.get(m.start(1), 0) + 1
    columns = []
    for at in sorted(starts):
        if columns and at - columns[-1][-1] <= SHIFT:
            columns[-1].append(at)
        else:
            columns.append([at])
    kept = [group[0] for group in columns if sum(starts[at] for at in group) >= 2]
    return [(at, following) for at, following in zip(kept, kept[1:] + [1 << 30])]


def _cell(lines):
    """A cell's text: its wrapped prose as one paragraph; an output or a list (a line that starts
    with ``/``, ``*``, ``-`` or holds a ``:``) keeps its lines."""
    lines = [line.strip() for line in lines if line.strip()]
    if any(re.match(r'^[/*\-]|^\S+\s*:|^-{3,}', line) for line in lines):
        return '\n'.join(lines)
    return ' '.join(lines)


def table_rows(layout, lowest=4, highest=9):
    """``[(number, text)]``: each row of the page's table whose first cell is a question's number (a
    table naming at least MIN_ROWS of questions ``lowest``-``highest``; ``[]`` when the page has none),
    its other cells' text, left to right."""
    lines = layout.splitlines()
    found = [(i, int(m.group(1)), m.start(1)) for i, line in enumerate(lines) for m in [_CELL.match(line)] if m]
    found = [(i, n, at) for i, n, at in found if 1 <= n <= 20]
    if not found:
        return []
    # the questions' column: where most numbers stand (a "3" of a wrapped "echo -n 3" stands elsewhere)
    places = [at for _, _, at in found]
    column = max(set(places), key=places.count)
    heads = [(i, n) for i, n, at in found if abs(at - column) <= 2]
    if len({n for _, n in heads if lowest <= n <= highest}) < MIN_ROWS:
        return []
    first = heads[0][0]
    top = next((i + 1 for i in range(first - 1, -1, -1) if _HEADER.match(lines[i])), first)
    centred = any(line.strip() for line in lines[top:first])
    owner = _owners(lines, top, heads, centred)
    spans = _columns([lines[i] for i in owner])
    number_at = _CELL.match(lines[first]).start(1)
    cells = [k for k, (a, b) in enumerate(spans) if not a <= number_at < b]
    if not cells or any(a <= number_at < b and b > number_at + 12 for a, b in spans) or \
            not any(a <= number_at < b for a, b in spans):
        return []  # the numbers stand in a column of prose ("Question 4" over its paragraph): no table
    rows = []
    for line_of, number in heads:
        part = [i for i, head in sorted(owner.items()) if head == line_of]
        texts = []
        for k in cells:
            texts.append(_cell([' '.join(token for column, token in _tokens(lines[i], spans) if column == k)
                                for i in part]))
        rows.append((number, '\n'.join(text for text in texts if text)))
    return rows


def _owners(lines, top, heads, centred):
    """``{line: its row's heading line}`` of the table's lines from ``top`` on: its blocks (lines between
    blank ones) each the row of the heading it holds, else of the nearest heading (cells centred on
    their row) or of the heading above it (cells on their row's top)."""
    starts = [line for line, _ in heads]
    blocks, current = [], []
    for i in range(top, len(lines)):
        if lines[i].strip():
            current.append(i)
        elif current:
            blocks.append(current)
            current = []
    if current:
        blocks.append(current)
    owner = {}
    for block in blocks:
        inside = [h for h in starts if block[0] <= h <= block[-1]]
        if len(inside) > 1:  # rows without a blank line between them: each line to its nearest heading
            for i in block:
                owner[i] = min(inside, key=lambda h: (abs(h - i), -h if centred else h))
            continue
        if inside:
            head = inside[0]
        elif centred:
            middle = (block[0] + block[-1]) / 2.0
            head = min(starts, key=lambda h: abs(h - middle))
        else:
            above = [h for h in starts if h <= block[0]]
            head = above[-1] if above else starts[0]
        for i in block:
            owner[i] = head
    return owner


def _tokens(line, spans):
    """``[(column, word)]`` of a line: each word in the column where it starts (a word that crosses a
    gutter is not cut)."""
    found = []
    for m in re.finditer(r'\S+', line):
        column = max([k for k, (a, _) in enumerate(spans) if a <= m.start()] or [0])
        found.append((column, m.group(0)))
    return found


def continued(layout):
    """The cells' text at the top of a page, before its table's first question (a row of the last
    page's table that went on here), or '' when the page starts with a question's row or has no
    columns (an ordinary page)."""
    lines = layout.splitlines()
    end = next((i for i, line in enumerate(lines) if _CELL.match(line) or _HEADER.match(line)), len(lines))
    part = [line for line in lines[:end] if line.strip()]
    spans = _columns(part)
    if len(spans) < 2:
        return ''
    return '\n'.join(text for text in (_cell([' '.join(t for c, t in _tokens(line, spans) if c == k) for line in part])
                                        for k in range(len(spans))) if text)
