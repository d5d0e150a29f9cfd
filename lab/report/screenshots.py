"""The grader's two page figures of docs/grading.md, each taken by headless Chromium and tagged with
what it shows, so that a docs test tells a figure of today's page from a stale one.

- docs/figures/feedback_page.png: docs/feedback_example.html, taken by lab/report/grading_examples.py
  right after it writes that page; tagged with the page's digest.
- docs/figures/grader_page.png: the class page of lab/test/grader's main class, taken by
  lab/test/grader/test_page_browser.py when GRADER_PAGE_SCREENSHOT names it; tagged with the digest of
  the code that draws the page (:data:`PAGE_CODE`), since the class page itself is not kept.

The tag is a PNG ``tEXt`` chunk (``exam_lab-source``), after the image header: viewers ignore it.
"""
import hashlib
import os
import shutil
import struct
import subprocess
import tempfile
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
FIGURES = os.path.join(REPO, 'docs', 'figures')
FEEDBACK_PNG = os.path.join(FIGURES, 'feedback_page.png')
PAGE_PNG = os.path.join(FIGURES, 'grader_page.png')
#: The modules that draw the class page and its plots: a change to one of them is a new figure.
PAGE_CODE = ('publish/page.py', 'publish/flightplot.py', 'publish/report.py')
KEY = b'exam_lab-source'
_SIGNATURE = b'\x89PNG\r\n\x1a\n'


def digest(*paths):
    """The first 16 hex digits of the SHA-256 of these files' bytes, each after its name."""
    value = hashlib.sha256()
    for path in paths:
        value.update(os.path.basename(path).encode() + b'\0')
        with open(path, 'rb') as f:
            value.update(f.read())
    return value.hexdigest()[:16]


def page_code_digest():
    grader = os.path.join(REPO, 'lab', 'src', 'exam_lab', 'grader')
    return digest(*(os.path.join(grader, p) for p in PAGE_CODE))


def chromium():
    return shutil.which('chromium') or shutil.which('chromium-browser')


def take(page, png, size, source, timeout=120):
    """Screenshot ``page`` (a file) at ``size`` ((width, height)) into ``png``, tagged ``source``.
    Raises RuntimeError, saying why, when Chromium is missing or draws nothing."""
    browser = chromium()
    if browser is None:
        raise RuntimeError('no chromium (tools/install_deps.sh installs it): %s not taken' % png)
    with tempfile.TemporaryDirectory(prefix='screenshot-') as scratch:
        shot = os.path.join(scratch, 'page.png')
        subprocess.run([browser, '--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
                        '--hide-scrollbars', '--virtual-time-budget=10000', '--user-data-dir=%s' % scratch,
                        '--window-size=%d,%d' % size, '--screenshot=%s' % shot, 'file://' + os.path.abspath(page)],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=timeout, check=False)
        if not os.path.isfile(shot):
            raise RuntimeError('chromium drew no screenshot of %s' % page)
        with open(shot, 'rb') as f:
            data = f.read()
    with open(png + '.tmp', 'wb') as f:
        f.write(tagged(data, source))
    os.replace(png + '.tmp', png)


def tagged(data, source):
    """The PNG ``data`` with a tEXt chunk ``KEY`` = ``source`` after its header (IHDR)."""
    if data[:8] != _SIGNATURE:
        raise ValueError('not a PNG')
    header_end = 8 + 12 + struct.unpack('>I', data[8:12])[0]
    body = KEY + b'\0' + source.encode('latin-1')
    chunk = struct.pack('>I', len(body)) + b'tEXt' + body + struct.pack('>I', zlib.crc32(b'tEXt' + body))
    return data[:header_end] + chunk + data[header_end:]


def tag(png):
    """The ``KEY`` text of a PNG file, or None."""
    with open(png, 'rb') as f:
        data = f.read()
    at = 8
    while data[:8] == _SIGNATURE and at + 8 <= len(data):
        length, kind = struct.unpack('>I4s', data[at:at + 8])
        if kind == b'tEXt':
            key, _, value = data[at + 8:at + 8 + length].partition(b'\0')
            if key == KEY:
                return value.decode('latin-1')
        if kind == b'IDAT':
            return None
        at += 12 + length
    return None
