"""Read a student's report, as its box's uid: every page's text, from the PDF's text layer or by OCR.

Root starts it in a box of its own (:func:`exam_lab.grader.host.reports.read_report`), without network,
within :data:`~exam_lab.grader.host.reports.REPORT_BOUNDS`::

    python3 -m exam_lab.grader.boxed.report_reader --upload U --out /box/out [--seconds S]

and reads back ``/box/out/report.json``, one :class:`~exam_lab.grader.score.records.ReportRecord`, and
the files it names in ``/box/out/report/``. What it reads:

- **The files.** Every report the student handed in: the files of the Moodle folder (a PDF, an ``.odt``
  or ``.docx``, a ``.doc`` or ``.rtf``, a picture) and the documents inside its archives (the package's
  zip often holds the PDF), each archive unpacked by :func:`~exam_lab.grader.boxed.archives.safe_extract`
  within one budget. A file's kind is read from its bytes, not its name; the same bytes twice are read
  once. A word processor's file is made a PDF by LibreOffice headless, here, its profile in the box's
  /tmp, made for it before it starts (:data:`OFFICE_PROFILE`).
- **Each page** (poppler's command-line tools, each bounded in time and memory): the text layer
  (``pdftotext -bbox-layout``: the words, their lines and where they stand; ``pdftotext -layout`` for
  the columns of a table). A page without text is rendered (``pdftoppm``, its longest side bounded
  whatever the page's size) and read by tesseract (French and English), every word with its
  confidence. A page with text and pictures (a terminal pasted as a screenshot) has the pictures read
  by OCR too, where they stand: the ink the text layer does not explain is found on the page's image,
  and each such region read from the picture of its shape as the PDF holds it (``pdfimages``: a
  screenshot at its own pixels), else cut out of the page (the text layer's words painted out).
  Light-on-dark pictures (a terminal) are grayscaled, inverted, enlarged twice and stretched first, so
  ``/pressure_remote``, underscores and ``0.778`` read as printed (a threshold loses the underscores).
- **Not read** (that file, or the whole report when no file was): an encrypted PDF, a broken one, one
  of more than :data:`~exam_lab.grader.score.records.REPORT_FILE_PAGES` pages or whose pages are huge,
  a tool killed by its bounds (a decompression bomb), a file of no kind the reader knows, a file with
  neither text nor picture. Each said in one sentence.

No rospy, nothing of root's. Not PyMuPDF (AGPL): poppler, tesseract and PIL only.
"""
import argparse
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import time

from exam_lab.grader.boxed import archives, bounds
from exam_lab.grader.boxed.report_files import FILE_BYTES, find_reports, kind_of, copy_name
from exam_lab.grader.boxed.report_text import ToolFailed, matching_picture, merge_pictures, ocr_facts, \
    parse_bbox, parse_tsv, join_underscores, records_clean, words_text
from exam_lab.grader.score import records
from exam_lab.grader.score.records import REPORT_FILE_PAGES, REPORT_PAGE_TEXT, REPORT_PAGES, REPORT_VERSION, \
    ReportRecord

#: The reading's own time (the box's wall clock is a little more): pages past it are said, not read.
SECONDS = 120.0
#: A page larger than this (points, either side: 200 inches) is not rendered.
MAX_PAGE_POINTS = 14400
#: Pixels of the longest side: a page's PNG for the review page; a page rendered for OCR (about 300 dpi
#: on A4, 215 dpi: tesseract reads it as well as at 300 and a third faster); a picture handed in (larger ones are not read).
PREVIEW_PIXELS = 1400
OCR_PIXELS = 2500
#: Pages pdftoppm renders at a time for the review page (their PPMs in the box's /tmp: 6 MB each at most).
RENDER_PAGES = 8
MAX_PICTURE_PIXELS = 40 * 1000 * 1000
#: A page whose text layer holds fewer letters and digits than this is read by OCR.
MIN_TEXT = 20
#: Each tool's bounds inside the box: (wall clock s, address space bytes).
TOOL_BOUNDS = {'pdfinfo': (20, 1 << 30), 'pdftotext': (60, 1 << 30), 'pdfimages': (20, 1 << 30),
               'pdftoppm': (60, 1536 << 20), 'tesseract': (60, 1536 << 20), 'soffice': (90, 3 << 30)}
#: A picture of a text page is read when it covers at least this (inches, both sides) and this share
#: of its cells holds ink.
MIN_PICTURE_INCHES = (0.8, 0.25)
MIN_PICTURE_INK = 0.2
_CELL = 8  # pixels of the page's PNG per cell of the ink grid
#: The installed LibreOffice (Debian's libreoffice-writer-nogui): its version and its build are read there.
OFFICE = '/usr/lib/libreoffice'
#: The profile LibreOffice starts from, made as its first start leaves it (the box's /tmp is new at each
#: reading, and so would be its profile): made already, last used by this version, its extensions synced
#: by this build. A new profile costs two starts (the first makes it, syncs the extensions and restarts
#: itself), and a profile a version has not used yet runs its graphics tests (GraphicsRenderTests: 109
#: drawings, 16 of them at 4096 x 4096 pixels, 1 GB of memory touched): a .docx's conversion took 1.2 s of
#: CPU, 0.4 s with this profile, the same PDF.
OFFICE_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<oor:items xmlns:oor="http://openoffice.org/2001/registry" xmlns:xs="http://www.w3.org/2001/XMLSchema" \
xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
<item oor:path="/org.openoffice.Setup/Office"><prop oor:name="ooSetupInstCompleted" oor:op="fuse"><value>true</value>\
</prop></item>
%s</oor:items>
"""
OFFICE_LAST_VERSION = '<item oor:path="/org.openoffice.Setup/Product"><prop oor:name="ooSetupLastVersion" ' \
                      'oor:op="fuse"><value>%s</value></prop></item>\n'


class Tools(object):
    """The reading's folders (``out/report/``: the copies and the pages' PNGs; ``out/scratch/``:
    conversions and renderings), its time (``seconds``) and its tools, each run within its bounds."""

    def __init__(self, out, seconds=SECONDS, workers=None):
        self.out, self.deadline = out, time.monotonic() + seconds
        self.report = os.path.join(out, 'report')
        self.scratch = os.path.join(out, 'scratch')
        for folder in (self.report, self.scratch):
            os.makedirs(folder, exist_ok=True)
        self.workers = workers or max(1, min(2, len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else 2))
        self.notes = []

    def left(self):
        return self.deadline - time.monotonic()

    def tool(self, name, args, output=None, what=None):
        """Run the tool ``name`` with ``args`` within its bounds and the reading's time; its stdout into
        the file ``output`` (or returned, decoded, when None: at most 16 MB). Raises ToolFailed."""
        wall, memory = TOOL_BOUNDS[name]
        wall = min(wall, self.left())
        if wall <= 1:
            raise ToolFailed('the reader\'s time (%d s) ran out' % SECONDS)
        argv = ['prlimit', '--as=%d' % memory, '--cpu=%d' % (int(wall) + 1), '--fsize=%d' % (64 << 20), '--',
                name] + list(args)
        env = {'PATH': '/usr/bin:/bin', 'HOME': os.environ.get('HOME', '/tmp'), 'OMP_THREAD_LIMIT': '1',
               'LANG': 'C.UTF-8', 'TMPDIR': self.scratch}
        sink = open(output, 'wb') if output else subprocess.PIPE
        try:
            done = subprocess.run(argv, stdin=subprocess.DEVNULL, stdout=sink, stderr=subprocess.PIPE,
                                  timeout=wall, env=env)
        except subprocess.TimeoutExpired:
            raise ToolFailed('%s took more than %d s' % (what or name, wall))
        finally:
            if output:
                sink.close()
        if done.returncode != 0:
            err = done.stderr.decode('utf-8', 'replace').strip().splitlines()
            last = [line for line in err if 'Warning' not in line and 'javaldx' not in line][-1:] or err[-1:]
            raise ToolFailed('%s %s%s' % (what or name, 'was killed (its bounds: %d s, %d MB)' % (wall, memory >> 20)
                                          if done.returncode < 0 or done.returncode > 128 else
                                          'failed (exit %d)' % done.returncode, ': %s' % last[0][:300] if last else ''))
        return None if output else done.stdout[:16 << 20].decode('utf-8', 'replace')


class Pages(object):
    """A PDF's pages: its text layer, its pictures, its pages' PNGs."""

    def read_pdf(self, index, path, count, info):
        """The pages of one PDF: the text layer, the pages' PNGs, OCR where there is no text."""
        for number, (w, h) in info['sizes'].items():
            if number <= count and max(w, h) > MAX_PAGE_POINTS:
                raise ToolFailed('page %d is %.0f x %.0f inches (at most %d): not read' % (number, w / 72, h / 72,
                                                                                       MAX_PAGE_POINTS // 72))
        layout = self.text(path, count, ['-layout'])
        boxes = self.word_boxes(path, count)
        texts = {number: '\n'.join(line['text'] for line in boxes.get(number, [])) for number in range(1, count + 1)}
        scanned = {number for number, text in texts.items() if len(re.findall(r'\w', text)) < MIN_TEXT}
        pictures = self.pictures(path, count, set(texts) - scanned)
        previews = self.render(index, path, count)
        pages, ocr = [], []
        for number in range(1, count + 1):
            lines = boxes.get(number, [])
            page = {'file': index, 'number': number, 'source': 'text', 'text': texts[number],
                    'layout': layout[number - 1] if number <= len(layout) else '',
                    'confidence': None, 'unsure': [], 'pictures': 0, 'image': previews.get(number)}
            pages.append(page)
            if number in scanned:
                page.update(source='ocr', layout='', text='')
                ocr.append((page, None))
            elif pictures.get(number) and page['image']:
                ocr.append((page, lines))
        with concurrent.futures.ThreadPoolExecutor(max_workers=self.workers) as pool:
            for _ in pool.map(lambda job: self.ocr_page(path, info, job[0], job[1], pictures.get(job[0]['number'], ())),
                              ocr):
                pass
        for page in pages:
            for key in ('text', 'layout'):
                page[key] = bounds.cut(records_clean(page[key]), REPORT_PAGE_TEXT)
        return pages

    def text(self, path, count, options):
        """Each page's text by ``pdftotext options`` (a list of ``count`` texts)."""
        output = os.path.join(self.scratch, 'text.txt')
        self.tool('pdftotext', options + ['-enc', 'UTF-8', '-f', '1', '-l', str(count), path, output],
                  what='pdftotext')
        with open(output, 'rb') as f:
            pages = f.read(8 * REPORT_PAGE_TEXT * count).decode('utf-8', 'replace').split('\f')
        return (pages + [''] * count)[:count]

    def word_boxes(self, path, count):
        """``{page: [{"text", "top", "bottom", "boxes": [(x0, y0, x1, y1)]}]}`` in points, in reading order:
        the text layer's lines (``pdftotext -bbox-layout``)."""
        output = os.path.join(self.scratch, 'bbox.html')
        self.tool('pdftotext', ['-bbox-layout', '-enc', 'UTF-8', '-f', '1', '-l', str(count), path, output],
                  what='pdftotext')
        return parse_bbox(output)

    def pictures(self, path, count, wanted):
        """``{page: [(width, height, file)]}``: the pictures of each page of ``wanted`` (those with a
        text layer: a page without is read whole from its rendering) large enough to hold text,
        extracted at their own resolution (``pdfimages``: a screenshot is read best as it was taken);
        a page with a picture too large to decode holds none (its page's image is read instead)."""
        try:
            listing = self.tool('pdfimages', ['-list', '-f', '1', '-l', str(count), path])
        except ToolFailed as err:
            self.notes.append('pictures not listed: %s' % err)
            return {}
        found, too_large = {}, set()
        for line in listing.splitlines()[2:]:
            fields = line.split()
            if len(fields) > 4 and fields[0].isdigit() and fields[1].isdigit() and fields[3].isdigit() \
                    and fields[4].isdigit() and fields[2] == 'image':
                page, num, w, h = int(fields[0]), int(fields[1]), int(fields[3]), int(fields[4])
                if w * h > MAX_PICTURE_PIXELS:
                    self.notes.append('page %d: a picture of %d x %d pixels (at most %d million): the page\'s image '
                                      'read instead' % (page, w, h, MAX_PICTURE_PIXELS // 10 ** 6))
                    too_large.add(page)
                elif w >= 100 and h >= 30:
                    found.setdefault(page, []).append((w, h, num))
        pages = sorted(set(found) & set(wanted) - too_large)
        prefix = os.path.join(self.scratch, 'picture')
        extracted = {}
        for page in pages:
            try:
                self.tool('pdfimages', ['-png', '-p', '-f', str(page), '-l', str(page), path, prefix],
                          what='extracting the pictures of page %d' % page)
            except ToolFailed as err:
                self.notes.append('page %d: pictures not extracted: %s' % (page, err))
                continue
            extracted[page] = [(w, h, os.path.join(self.scratch, 'picture-%03d-%03d.png' % (page, num)))
                               for w, h, num in found[page]]
        return {page: [p for p in pictures if os.path.isfile(p[2])] for page, pictures in extracted.items()}

    def render(self, index, path, count):
        """``{page: "report/page-<file>-<page>.png"}``: each page's PNG, its longest side PREVIEW_PIXELS.
        pdftoppm renders RENDER_PAGES pages at a time to PPM (its own PNG encoder takes ten times the
        rendering: 0.44 s a scanned page) and PIL writes each PNG (0.04 s; zlib's level 1: as small as its
        default on a scan, twice as fast), its PPM removed at once (the box's /tmp holds a few pages' PPMs,
        never a file's 40)."""
        from exam_lab.grader.boxed import report_images
        prefix = os.path.join(self.scratch, 'preview%d' % index)
        done = {}
        for first in range(1, count + 1, RENDER_PAGES):
            last = min(count, first + RENDER_PAGES - 1)
            failed = False
            try:
                self.tool('pdftoppm', ['-scale-to', str(PREVIEW_PIXELS), '-f', str(first), '-l', str(last), path, prefix],
                          what='rendering its pages')
            except ToolFailed as err:
                failed = True
                self.notes.append('%s: pages not rendered: %s' % (os.path.basename(path), err))
            for name in sorted(os.listdir(self.scratch)):
                match = re.match(r'^preview%d-0*(\d+)\.ppm$' % index, name)
                if match and first <= int(match.group(1)) <= last:
                    number, source = int(match.group(1)), os.path.join(self.scratch, name)
                    target = 'page-%d-%d.png' % (index + 1, number)
                    try:
                        report_images.open_image(source, MAX_PICTURE_PIXELS).save(os.path.join(self.report, target),
                                                                                 compress_level=1)
                        done[number] = 'report/' + target
                    except report_images.PictureError as err:  # a page pdftoppm cut short as it failed
                        self.notes.append('%s: page %d not rendered: %s' % (os.path.basename(path), number, err))
                    os.remove(source)
            if failed:
                break
        return done


class Ocr(object):
    """What tesseract reads: a page without text, the pictures of a text page, a picture handed in."""

    def ocr_page(self, path, info, page, lines, pictures=()):
        """OCR of a page without text (``lines`` None), or of the pictures of a text page, each where it
        stands (:func:`~exam_lab.grader.boxed.report_images.picture_regions`): read from the picture
        itself when one of ``pictures`` (:meth:`pictures`) has its shape, else cut out of the page."""
        from exam_lab.grader.boxed import report_images
        stem = os.path.join(self.scratch, 'ocr-%d-%d' % (page['file'], page['number']))
        rendered = []

        def page_image():
            if not rendered:
                self.tool('pdftoppm', ['-gray', '-scale-to', str(OCR_PIXELS), '-f', str(page['number']), '-l',
                                       str(page['number']), '-singlefile', path, stem],
                          what='rendering page %d' % page['number'])
                rendered.append(report_images.open_image(stem + '.pgm', MAX_PICTURE_PIXELS))
                os.remove(stem + '.pgm')
            return rendered[0]
        try:
            w, h = info['sizes'].get(page['number'], (595.0, 842.0))
            if lines is None:
                words = self.tesseract(report_images.prepare_page(page_image()), stem, 3)
                page.update(text=words_text(words), **ocr_facts(words, _where(page, path), self.notes))
                return
            boxes = [b for line in lines for b in line['boxes']]
            regions = report_images.picture_regions(
                report_images.open_image(os.path.join(self.out, page['image']), MAX_PICTURE_PIXELS), boxes, w,
                MIN_PICTURE_INCHES, MIN_PICTURE_INK, _CELL)
            left = list(pictures)
            blocks, everything = [], []
            for n, region in enumerate(regions + [None] * len(pictures)):
                if region is None and not left:
                    break
                match = matching_picture(region, left) if region is not None else left[0]
                if match is not None:
                    left.remove(match)
                    image = report_images.prepare_picture(report_images.open_image(match[2], MAX_PICTURE_PIXELS))
                else:
                    image = report_images.prepare_picture(report_images.cut_out(
                        page_image(), region, boxes, page_image().size[0] / w))
                words = self.tesseract(image, '%s-%d' % (stem, n), 6)
                if words:
                    blocks.append((region[1] if region is not None else h, words_text(words)))
                    everything += words
            if blocks:
                page.update(text=merge_pictures(lines, blocks), pictures=len(blocks),
                            **ocr_facts(everything, _where(page, path), self.notes))
        except (ToolFailed, report_images.PictureError) as err:
            self.notes.append('%s: not read by OCR: %s' % (_where(page, path), err))

    def tesseract(self, image, stem, psm):
        """The words tesseract reads in the PIL ``image`` (:data:`Word`), underscores it dropped put back."""
        from exam_lab.grader.boxed import report_images
        image.save(stem + '-in.pnm')  # not a PNG: its encoding took 0.15 s a page, an eighth of tesseract's time
        self.tool('tesseract', [stem + '-in.pnm', stem, '-l', 'fra+eng', '--psm', str(psm),
                                '-c', 'preserve_interword_spaces=1', 'tsv'], what='tesseract')
        with open(stem + '.tsv', 'rb') as f:
            words = parse_tsv(f.read(4 << 20).decode('utf-8', 'replace'))
        return join_underscores(words, lambda a, b: report_images.underscore_between(image, a, b))

    def read_picture(self, index, path):
        """A picture handed in as (part of) the report: one page, read by OCR."""
        from exam_lab.grader.boxed import report_images
        try:
            image = report_images.open_image(path, MAX_PICTURE_PIXELS)
        except report_images.PictureError as err:
            raise ToolFailed(str(err))
        target = 'page-%d-1.png' % (index + 1)
        report_images.preview(image, PREVIEW_PIXELS).save(os.path.join(self.report, target))
        words = self.tesseract(report_images.prepare_picture(image), os.path.join(self.scratch, 'picture%d' % index), 6)
        return dict({'file': index, 'number': 1, 'source': 'ocr', 'text': bounds.cut(records_clean(words_text(words)),
                                                                                    REPORT_PAGE_TEXT),
                     'layout': '', 'pictures': 0, 'image': 'report/' + target},
                    **ocr_facts(words, os.path.basename(path), self.notes))


class Reader(Pages, Ocr, Tools):
    """One submission's report read into ``out`` within ``seconds``."""

    def read(self, upload):
        """The record's value of the reports in ``upload``."""
        files, pages, beyond = [], [], []
        found = find_reports(upload, self.scratch, self.notes, beyond)
        if not found:
            return self.value('; '.join(beyond) or 'no report handed in (no PDF, no document, no picture among the '
                              'files)', files, pages)
        for index, (name, path) in enumerate(found):
            entry = {'name': bounds.cut(name, 255), 'kind': kind_of(path), 'converted': False, 'pages': 0, 'note': '',
                     'state': 'not read', 'copy': None}
            files.append(entry)
            try:
                size = os.path.getsize(path)
                if size > FILE_BYTES:
                    raise ToolFailed('%d bytes, over the %d the reader reads of one file' % (size, FILE_BYTES))
                entry['copy'] = self.keep(index, name, path)
                read = self.read_file(index, entry, path, REPORT_PAGES - len(pages))
            except ToolFailed as err:
                entry['note'] = bounds.cut('%s: %s' % (archives.shown_name(name), err))
                continue
            pages.extend(read)
            entry['pages'] = len(read)
            if any(p['text'].strip() for p in read):
                entry['state'] = 'read'
            else:
                entry['note'] = entry['note'] or '%s: no text and no picture the reader can read' % archives.shown_name(name)
        if any(f['state'] == 'read' for f in files):
            return self.value('', files, [p for p in pages if files[p['file']]['state'] == 'read'])
        why = '; '.join(f['note'] for f in files if f['note']) or 'nothing could be read'
        return self.value(bounds.cut(why), files, [])

    def value(self, why, files, pages):
        return {'version': REPORT_VERSION, 'state': 'read' if pages else 'not read', 'why': why if not pages else '',
                'files': files, 'pages': pages, 'notes': self.notes, 'seconds': 0.0}

    def keep(self, index, name, path):
        """The file as handed in, copied to report/ (root copies it to OUT read-only)."""
        copy = copy_name(index, name)
        shutil.copyfile(path, os.path.join(self.report, copy))
        return 'report/' + copy

    def read_file(self, index, entry, path, room):
        kind = entry['kind']
        if kind in ('odt', 'docx', 'doc', 'rtf'):
            path = self.convert(index, path)
            entry['converted'] = True
        elif kind == 'image':
            return [self.read_picture(index, path)]
        elif kind != 'pdf':
            raise ToolFailed('not a PDF, a document or a picture the reader reads (a report is read from a PDF)')
        info = self.pdf_info(path)
        count = info['pages']
        if count > REPORT_FILE_PAGES:
            raise ToolFailed('%d pages, the reader reads %d' % (count, REPORT_FILE_PAGES))
        if count > room:
            self.notes.append('%s: pages %d-%d not read (the report\'s %d pages are read at most)'
                              % (archives.shown_name(entry['name']), room + 1, count, REPORT_PAGES))
            count = room
        return self.read_pdf(index, path, count, info)

    def convert(self, index, path):
        """``path`` made a PDF by LibreOffice headless (its profile in the box's /tmp: OFFICE_PROFILE)."""
        profile = os.path.join(self.scratch, 'lo-profile')
        if not os.path.isdir(profile):
            office_profile(profile)
        target = os.path.join(self.scratch, 'converted%d' % index)
        os.makedirs(target)
        source = os.path.join(target, 'report%s' % {'odt': '.odt', 'docx': '.docx', 'doc': '.doc', 'rtf': '.rtf'}
                              [kind_of(path)])
        shutil.copyfile(path, source)
        self.tool('soffice', ['--headless', '--norestore', '--nolockcheck',
                              '-env:UserInstallation=file://%s' % profile,
                              '--convert-to', 'pdf', '--outdir', target, source], what='LibreOffice\'s conversion to PDF')
        pdf = os.path.join(target, 'report.pdf')
        if not os.path.isfile(pdf):
            raise ToolFailed('LibreOffice made no PDF of it')
        return pdf

    def pdf_info(self, path):
        """``{"pages", "sizes": {page: (w, h) points}}``; ToolFailed for an encrypted or broken PDF."""
        try:
            text = self.tool('pdfinfo', ['-f', '1', '-l', str(REPORT_FILE_PAGES + 1), path])
        except ToolFailed as err:
            if 'password' in str(err).lower():
                raise ToolFailed('an encrypted PDF (it opens with a password): ask for it without one')
            raise ToolFailed('a broken PDF (%s)' % err)
        pages = re.search(r'^Pages:\s+(\d+)', text, re.M)
        if not pages:
            raise ToolFailed('a broken PDF (no page count)')
        sizes = {int(n): (float(w), float(h)) for n, w, h in
                 re.findall(r'^Page\s+(\d+) size:\s+([\d.]+) x ([\d.]+)', text, re.M)}
        return {'pages': int(pages.group(1)), 'sizes': sizes}


def _where(page, path):
    """A page of a file, as a note names it: "page 2 of report.pdf"."""
    return 'page %d of %s' % (page['number'], os.path.basename(path))


def office_profile(profile, office=OFFICE):
    """Make ``profile`` the LibreOffice profile OFFICE_PROFILE says, for the LibreOffice installed in
    ``office``; what cannot be read of it (its version, its build) is left for LibreOffice to do."""
    version = _first_match(os.path.join(office, 'share', 'registry', 'main.xcd'),
                           rb'<prop oor:name="ooSetupVersion">\s*<value>(\d{1,3}\.\d{1,3})</value>')
    build = _first_match(os.path.join(office, 'program', 'versionrc'), rb'(?m)^buildid=([^\r\n]{1,100})$')
    os.makedirs(os.path.join(profile, 'user', 'extensions'))
    with open(os.path.join(profile, 'user', 'registrymodifications.xcu'), 'w') as f:
        f.write(OFFICE_PROFILE % (OFFICE_LAST_VERSION % version if version else ''))
    if build:
        with open(os.path.join(profile, 'user', 'extensions', 'buildid'), 'w') as f:
            f.write(build)


def _first_match(path, pattern):
    """The first group of ``pattern``'s first match in the file ``path`` (ASCII), or None."""
    try:
        with open(path, 'rb') as f:
            found = re.search(pattern, f.read(16 << 20))
    except OSError:
        return None
    return found.group(1).decode('ascii', 'replace') if found else None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--upload', required=True, help='the submission: a folder, or one file')
    parser.add_argument('--out', required=True)
    parser.add_argument('--seconds', type=float, default=SECONDS, help='the reading\'s own time')
    args = parser.parse_args(argv)
    if os.getuid() == 0:
        sys.stderr.write('report_reader: refusing to read a student\'s report as root\n')
        return 2
    start = time.monotonic()
    reader = Reader(args.out, args.seconds)
    value = reader.read(args.upload)
    value['seconds'] = round(time.monotonic() - start, 2)
    try:
        records.write(args.out, ReportRecord, bounds.fit(value, ReportRecord))
    except records.RecordError as err:
        sys.stderr.write('report_reader: its record exceeds a bound: %s\n' % err)
        return 4
    finally:
        shutil.rmtree(reader.scratch, ignore_errors=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
