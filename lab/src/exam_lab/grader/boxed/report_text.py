"""The report reader's text, pure: the text layer's lines (``pdftotext -bbox-layout``), tesseract's
words (its TSV) with their confidence, the underscores it drops put back, a picture's text put where
the picture stands. No rospy, no tool run (:mod:`~exam_lab.grader.boxed.report_reader` runs them).
"""
import collections
import xml.etree.ElementTree as ET

from exam_lab.grader.boxed import bounds
from exam_lab.grader.score.records import REPORT_UNSURE
from exam_lab.grader.score.safe_text import clean

#: Under this confidence (tesseract's 0-100), an OCR word is listed as unsure.
CONFIDENCE_FLOOR = 60


class ToolFailed(Exception):
    """A tool that failed, or was killed by its bounds: the message is for the teacher."""


def records_clean(text):
    """A page's text without control characters (the form feed of a page's end among them)."""
    return clean(text.replace('\f', '')).strip('\n')


def parse_bbox(path):
    """The lines of ``pdftotext -bbox-layout``'s XHTML (see :meth:`Reader.word_boxes`), each page's
    flows and blocks in their order."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as err:
        raise ToolFailed('its text layer could not be read (%s)' % err)
    pages = {}
    for number, page in enumerate(root.iter('{http://www.w3.org/1999/xhtml}page'), 1):
        lines = []
        for line in page.iter('{http://www.w3.org/1999/xhtml}line'):
            words = [(w.text or '', tuple(float(w.get(k, 0)) for k in ('xMin', 'yMin', 'xMax', 'yMax')))
                     for w in line.iter('{http://www.w3.org/1999/xhtml}word')]
            if words:
                lines.append({'text': ' '.join(t for t, _ in words), 'top': float(line.get('yMin', 0)),
                              'bottom': float(line.get('yMax', 0)), 'boxes': [b for _, b in words]})
        pages[number] = lines
    return pages


#: One word of tesseract's: where it is in its block, paragraph and line, its text, its confidence, its
#: box ``(left, top, width, height)`` in the image's pixels.
Word = collections.namedtuple('Word', 'block paragraph line text confidence box')


def parse_tsv(tsv):
    """tesseract's TSV: its words (:data:`Word`), in its order."""
    words = []
    for row in tsv.splitlines()[1:]:
        fields = row.split('\t')
        if len(fields) < 12 or fields[0] != '5':
            continue
        try:
            confidence = float(fields[10])
            box = tuple(int(v) for v in fields[6:10])
            where = tuple(int(v) for v in fields[2:5])
        except ValueError:
            continue
        text = fields[11].strip()
        if text and confidence >= 0:
            words.append(Word(where[0], where[1], where[2], text, min(100.0, confidence), box))
    return words


def join_underscores(words, underscore):
    """``words`` with each pair of neighbours on a line that ``underscore(left box, right box)`` says are
    joined by an underscore (tesseract drops the underscores of ``/pressure_remote``: it reads
    ``/pressure remote``) made one word, ``pressure_remote``."""
    out = []
    for word in words:
        last = out[-1] if out else None
        if last is not None and last[:3] == word[:3] and underscore(last.box, word.box):
            left, top = min(last.box[0], word.box[0]), min(last.box[1], word.box[1])
            right = max(last.box[0] + last.box[2], word.box[0] + word.box[2])
            bottom = max(last.box[1] + last.box[3], word.box[1] + word.box[3])
            out[-1] = last._replace(text=last.text.rstrip('_') + '_' + word.text.lstrip('_'),
                                    confidence=min(last.confidence, word.confidence),
                                    box=(left, top, right - left, bottom - top))
        else:
            out.append(word)
    return out


def words_text(words):
    """The words as lines (a line of tesseract's a line of text), paragraphs apart by a blank line."""
    out, last = [], None
    for word in words:
        key, text = tuple(word[:3]), word.text
        if last is None:
            out.append(text)
        elif key == last:
            out[-1] += ' ' + text
        else:
            out.append(('\n' if key[:2] != last[:2] else '') + text)
        last = key
    return '\n'.join(out)


def ocr_facts(words, where='the page', notes=None):
    """``{"confidence", "unsure"}`` of OCR words: their mean confidence, those under the floor (each
    once, at most REPORT_UNSURE); when more were, ``notes`` gets a sentence saying how many, of
    ``where``: a cap is said, never a silent cut."""
    if not words:
        return {'confidence': None, 'unsure': []}
    unsure = list(dict.fromkeys(w.text for w in words if w.confidence < CONFIDENCE_FLOOR))
    if len(unsure) > REPORT_UNSURE and notes is not None:
        notes.append('%s: %d words read by OCR with low confidence, the first %d listed'
                     % (where, len(unsure), REPORT_UNSURE))
    return {'confidence': round(sum(w.confidence for w in words) / len(words), 1),
            'unsure': [bounds.cut(records_clean(text), 100) for text in unsure[:REPORT_UNSURE]]}


def matching_picture(region, pictures):
    """The one of ``pictures`` (``(width, height, file)``) whose shape is the ``region``'s (within 25%),
    the closest; None when none is."""
    x0, y0, x1, y1 = region
    wanted = (x1 - x0) / max(1e-6, y1 - y0)
    best = min(pictures, key=lambda p: abs(p[0] / float(p[1]) / wanted - 1), default=None)
    return best if best is not None and abs(best[0] / float(best[1]) / wanted - 1) <= 0.25 else None


def merge_pictures(lines, blocks):
    """The page's text with each picture's OCR (``[(top in points, text)]``) put before the first line
    of the text layer below the picture's top, between ``[picture N, OCR]`` and ``[end of picture N]``."""
    blocks = sorted(blocks)
    out, n = [], 0
    for line in lines:
        while n < len(blocks) and blocks[n][0] <= line['top']:
            out.append('[picture %d, OCR]\n%s\n[end of picture %d]' % (n + 1, blocks[n][1], n + 1))
            n += 1
        out.append(line['text'])
    for k in range(n, len(blocks)):
        out.append('[picture %d, OCR]\n%s\n[end of picture %d]' % (k + 1, blocks[k][1], k + 1))
    return '\n'.join(out)
