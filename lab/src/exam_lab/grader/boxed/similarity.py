"""Similarity across a class: pairs of submissions whose code is suspiciously alike. No rospy here.

The detector is copydetect (PyPI, pinned :data:`VERSION`): winnowing over the tokens of the code, in
the style of MOSS, with names, strings and comments normalised away (renaming variables or rewording
comments does not hide a copy) and a boilerplate set whose fingerprints never count. It is installed
on first use into a virtual environment of its own (``$EXAM_WS/similarity-venv``, seeing Debian's
packages: made by root, :mod:`~exam_lab.grader.host.similarity_setup`, never by this box's code), and runs there as ``python -m exam_lab.grader.boxed.similarity JOB.json``; the grader's own
Python needs nothing new.

What every student got is boilerplate (made by root: :func:`~exam_lab.grader.host.similarity_setup.boilerplate`):
``catkin_create_pkg``'s CMakeLists.txt and package.xml (made anew, for both sheets), the launch file's skeleton, and the code of the sheets' packages (the
drones, which students read and copy idioms from). Only a package's code is compared: Python, C++,
launch files, CMakeLists.txt and package.xml; never its data (YAML, maps, logs, bags). What is read of
one student is bounded (MAX_STUDENT_FILES, MAX_STUDENT_BYTES, its code first): a student who hands in
megabytes of anything costs the check what a large package costs, and cannot switch it off for the
others.

A pair is flagged when the code of one of the two is at least :data:`THRESHOLD` alike the other's (the
share of its fingerprinted tokens found in the other). It flags; it never changes a grade.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

from exam_lab.grader.boxed import archives, bounds
from exam_lab.grader.boxed.package import open_submission
from exam_lab.grader.score import records
from exam_lab.grader.score.names import CODE_NAMES, CODE_SUFFIXES, VERSION

#: copydetect's noise threshold (k, characters of normalised code) and window.
NOISE = 25
WINDOW = 4
#: Share of a submission's fingerprinted code found in the other's, from which a pair is flagged.
THRESHOLD = 0.5
#: Files compared (code, not data: score.names), and the most bytes read of one.
MAX_FILE_BYTES = 200 * 1024
#: What is compared of one student at most (a package's code is a few files of a few kB), its
#: programs first (:func:`student_code`).
MAX_STUDENT_FILES = 50
MAX_STUDENT_BYTES = 512 * 1024
#: What similarity.json keeps of the pairs' highlighted code and of every pair's scores, within its
#: record's bytes (:class:`~exam_lab.grader.score.records.SimilarityRecord`: 32 MB): the most alike first.
MAX_HTML_BYTES = 16 << 20
MAX_SCORES_BYTES = 8 << 20
#: Languages by suffix, for files pygments does not know by name.
LANGUAGES = {'.launch': 'xml', '.xml': 'xml', '.txt': 'cmake', '.py': 'python', '.cpp': 'cpp', '.cc': 'cpp',
             '.cxx': 'cpp', '.c': 'cpp', '.h': 'cpp', '.hpp': 'cpp'}
class SimilarityError(Exception):
    """The detector could not be installed or run."""


def code_files(package, large=None):
    """The package's code files that are compared, relative to it; those over MAX_FILE_BYTES (data,
    not code a student writes) are not, and go into ``large`` when given."""
    found = []
    for dirpath, dirnames, filenames in os.walk(package):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.') and d not in ('build', 'devel'))
        for name in sorted(filenames):
            full = os.path.join(dirpath, name)
            if (name.endswith(CODE_SUFFIXES) or name in CODE_NAMES) and not os.path.islink(full):
                if os.path.getsize(full) <= MAX_FILE_BYTES:
                    found.append(os.path.relpath(full, package))
                elif large is not None:
                    large.append(os.path.relpath(full, package))
    return sorted(found)


def student_code(package, large=None):
    """``(files compared, files left out)`` of one student's package: its code files, programs
    (Python, C++) before launch files and the build files, within MAX_STUDENT_FILES and
    MAX_STUDENT_BYTES (those over MAX_FILE_BYTES into ``large``: :func:`code_files`)."""
    order = {'.launch': 1, '.xml': 2, '.txt': 2}
    found = sorted(code_files(package, large), key=lambda r: (order.get(os.path.splitext(r)[1], 0), r))
    taken, left, size = [], [], 0
    for relative in found:
        nbytes = os.path.getsize(os.path.join(package, relative))
        if len(taken) < MAX_STUDENT_FILES and size + nbytes <= MAX_STUDENT_BYTES:
            taken.append(relative)
            size += nbytes
        else:
            left.append(relative)
    return sorted(taken), left


def stage(submissions, target):
    """Copy each submission's package code into ``target/<n>/`` (:func:`student_code`); what was
    unpacked to find it is removed before the next student's.

    :param submissions: ``[(name, folder or zip)]``.
    :returns: ``({name: staged folder}, [notes on submissions left out or cut])``.
    """
    staged, notes = {}, []
    for index, (name, path) in enumerate(submissions):
        notes_here = []
        scratch = os.path.join(target, 'unpacked-%d' % index)
        try:
            package = open_submission(path, scratch, notes_here)
            large = []
            taken, left = student_code(package, large)
            folder = os.path.join(target, 'code', str(index))
            for relative in taken:
                os.makedirs(os.path.dirname(os.path.join(folder, relative)), exist_ok=True)
                shutil.copyfile(os.path.join(package, relative), os.path.join(folder, relative))
        except Exception as err:  # a refused or odd upload is compared by nobody, and said so
            notes.append('%s: not compared (%s)' % (name, err))
            continue
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        if left:
            notes.append('%s: %d code file(s) compared, %d left out (at most %d files and %d bytes of a student): %s'
                         % (name, len(taken), len(left), MAX_STUDENT_FILES, MAX_STUDENT_BYTES,
                            archives.listed([archives.shown_name(r) for r in left])))
        if large:
            notes.append('%s: %d code file(s) not compared, each over the %d bytes the check reads of one file: %s'
                         % (name, len(large), MAX_FILE_BYTES, archives.listed([archives.shown_name(r) for r in large])))
        if os.path.isdir(folder):
            staged[name] = folder
        else:
            notes.append('%s: no code to compare' % name)
    return staged, notes


def check(submissions, out_dir, python, shared, scratch_dir=None):
    """Compare every pair of ``submissions`` (``[(name, folder or zip)]``); write
    ``out_dir/similarity.json`` and return it: ``{"pairs": [...], "students", "threshold", "notes"}``
    or ``{"error": why}`` when the detector could not run (the grades stand either way).

    :param python: the detector's venv's Python (:func:`~exam_lab.grader.host.similarity_setup.ensure_venv`, root's).
    :param shared: the boilerplate folder (:func:`~exam_lab.grader.host.similarity_setup.boilerplate`, root's).
    :param scratch_dir: where the submissions are unpacked (the system's temp folder when None).
    """
    scratch = tempfile.mkdtemp(prefix='similarity-', dir=scratch_dir)
    try:
        staged, notes = stage(submissions, scratch)
        job = {'students': staged, 'boilerplate': shared,
               'noise': NOISE, 'window': WINDOW, 'threshold': THRESHOLD, 'result': os.path.join(scratch, 'result.json')}
        with open(os.path.join(scratch, 'job.json'), 'w') as f:
            json.dump(job, f)
        try:
            env = dict(os.environ, PYTHONPATH=os.pathsep.join(
                [os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))] +
                [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p]))
            done = subprocess.run([python, '-m', 'exam_lab.grader.boxed.similarity', os.path.join(scratch, 'job.json')],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=900)
            if done.returncode != 0 or not os.path.isfile(job['result']):
                raise SimilarityError('the detector failed (exit %d): %s' % (
                    done.returncode, done.stdout.decode('utf-8', 'replace')[-1500:]))
            with open(job['result']) as f:
                result = json.load(f)
        except (SimilarityError, subprocess.SubprocessError) as err:
            result = {'error': str(err)}
        result['notes'] = notes
        result = bounds.fit(bounded(result), records.SimilarityRecord)
        with open(os.path.join(out_dir, 'similarity.json'), 'w') as f:
            json.dump(result, f, indent=1, sort_keys=True)
        return result
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def bounded(result):
    """``result`` (the detector's, with its ``notes``) within what similarity.json holds, each cut a
    sentence in its notes: the flagged pairs most alike first (at most the record's number), their
    highlighted code within MAX_HTML_BYTES (a fragment over the record's length is left out, not cut:
    its markup would break), every pair's scores most alike first within MAX_SCORES_BYTES."""
    notes = []  # what was cut of the class, before what was said of each student
    schema = records.SimilarityRecord.SCHEMA
    pairs = sorted(result.get('pairs') or [], key=lambda p: -max(p['score_a'], p['score_b']))
    if 'pairs' in result:
        result['pairs'] = pairs = bounds.kept(pairs, 'pairs flagged', notes, schema['pairs'].schema.limit,
                                              verb='kept, the most alike')
    html_limit, spent, dropped = schema['pairs'].schema.schema['files'][0]['html_a'].limit, 0, 0
    for pair in pairs:
        for match in pair['files']:
            for key in ('html_a', 'html_b'):
                size = len(json.dumps(match[key]))  # as written: a character not ASCII is 6 bytes
                if len(match[key]) > html_limit or spent + size > MAX_HTML_BYTES:
                    match[key] = '(its highlighted code, %d characters, is not kept: at most %d characters of a '\
                                 'file, %d bytes of the class)' % (len(match[key]), html_limit, MAX_HTML_BYTES)
                    dropped += 1
                else:
                    spent += size
    if dropped:
        notes.append('%d highlighted fragments not kept (at most %d characters of one, %d bytes of the class): '
                     'the most alike pairs keep theirs' % (dropped, html_limit, MAX_HTML_BYTES))
    scores = sorted(result.get('scores') or [], key=lambda s: -max(s[2], s[3]))
    limit, size = schema['scores'].schema.limit, 0
    for index, row in enumerate(scores[:limit]):
        size += len(json.dumps(row)) + 2
        if size > MAX_SCORES_BYTES:
            limit = index
            break
    if len(scores) > limit:  # else in the detector's order
        result['scores'] = bounds.kept(scores, "pairs' scores (%d bytes at most)" % MAX_SCORES_BYTES, notes, limit,
                                       verb='kept, the most alike')
    result['notes'] = bounds.closed(notes + result.get('notes', []), keep=notes)
    return result


# --- inside the detector's environment -------------------------------------------------------------

def _fingerprints(folder, noise, window, hashes):
    from copydetect import CodeFingerprint
    prints = {}
    for relative in code_files(folder):
        language = LANGUAGES.get(os.path.splitext(relative)[1], 'cmake')
        try:
            fp = CodeFingerprint(os.path.join(folder, relative), noise, window, hashes, language=language)
        except (UnicodeDecodeError, ValueError):
            continue
        if fp.token_coverage > 0:
            prints[relative] = fp
    return prints


def compare(job):
    """The detector's work (runs where copydetect is installed): every pair of students, every pair of
    their files of one language; a student's score is the share of its fingerprinted code found in
    the other's (each file counted by its best match)."""
    import numpy as np
    from copydetect import CodeFingerprint, compare_files
    from copydetect.utils import highlight_overlap

    hashes = []
    for relative in code_files(job['boilerplate']):
        language = LANGUAGES.get(os.path.splitext(relative)[1], 'cmake')
        try:
            hashes.extend(CodeFingerprint(os.path.join(job['boilerplate'], relative), job['noise'], 1,
                                          language=language).hashes)
        except (UnicodeDecodeError, ValueError):
            continue
    hashes = np.unique(np.array(hashes))
    prints = {name: _fingerprints(folder, job['noise'], job['window'], hashes)
              for name, folder in sorted(job['students'].items())}
    names = sorted(prints)
    pairs = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            best_a, best_b, matches = {}, {}, []
            for file_a, fp_a in prints[a].items():
                for file_b, fp_b in prints[b].items():
                    if LANGUAGES.get(os.path.splitext(file_a)[1]) != LANGUAGES.get(os.path.splitext(file_b)[1]):
                        continue
                    overlap, (sim_a, sim_b), (slices_a, slices_b) = compare_files(fp_a, fp_b)
                    if overlap <= 0:
                        continue
                    tokens_a = sim_a * fp_a.token_coverage
                    tokens_b = sim_b * fp_b.token_coverage
                    best_a[file_a] = max(best_a.get(file_a, 0.0), tokens_a)
                    best_b[file_b] = max(best_b.get(file_b, 0.0), tokens_b)
                    matches.append((float(max(tokens_a, tokens_b)), file_a, file_b, float(sim_a), float(sim_b),
                                    slices_a, slices_b, fp_a, fp_b))
            cover_a = sum(fp.token_coverage for fp in prints[a].values()) or 1
            cover_b = sum(fp.token_coverage for fp in prints[b].values()) or 1
            score_a, score_b = sum(best_a.values()) / cover_a, sum(best_b.values()) / cover_b
            job.setdefault('scores', []).append([a, b, float(score_a), float(score_b)])
            if max(score_a, score_b) < job['threshold']:
                continue
            matches.sort(key=lambda m: -m[0])
            files = []
            for _, file_a, file_b, sim_a, sim_b, slices_a, slices_b, fp_a, fp_b in matches[:3]:
                html_a, _ = highlight_overlap(fp_a.raw_code, slices_a, "<span class='highlight-red'>", '</span>',
                                              escape_html=True)
                html_b, _ = highlight_overlap(fp_b.raw_code, slices_b, "<span class='highlight-green'>",
                                              '</span>', escape_html=True)
                files.append({'file_a': file_a, 'file_b': file_b, 'sim_a': sim_a, 'sim_b': sim_b,
                              'html_a': html_a, 'html_b': html_b})
            pairs.append({'a': a, 'b': b, 'score_a': float(score_a), 'score_b': float(score_b), 'files': files})
    pairs.sort(key=lambda p: -max(p['score_a'], p['score_b']))
    return {'pairs': pairs, 'students': len(names), 'threshold': job['threshold'],
            'detector': 'copydetect ' + VERSION, 'scores': job.get('scores', [])}


def main(argv):
    if len(argv) == 2 and argv[0] == '--class':  # the whole check, in the class's box (class_run's)
        with open(argv[1]) as f:
            job = json.load(f)
        check([tuple(s) for s in job['submissions']], job['out'], job['python'], job['boilerplate'], job['out'])
        return 0
    if len(argv) != 1:
        sys.stderr.write('usage: python -m exam_lab.grader.boxed.similarity [--class] JOB.json\n')
        return 2
    with open(argv[0]) as f:
        job = json.load(f)
    result = compare(job)
    with open(job['result'], 'w') as f:
        json.dump(result, f)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
