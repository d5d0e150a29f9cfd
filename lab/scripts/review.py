#!/usr/bin/env python3
"""The teacher's review of the hand points, on a page served to this machine only (docs/grading.md,
"Reviewing the hand points").

    review.py --out OUT                (make review OUT=...)
    review.py --out OUT --agreement    (make review OUT=... AGREEMENT=1)

Serves the review page on 127.0.0.1, on a free port, at a URL with a random token that it prints;
Ctrl-C stops it. Each point confirmed or changed there is written into OUT/hand.csv, and kept with
the proposal it was made on in OUT/review.json. ``--agreement`` prints, per item, how often the
teacher's points were the proposals' (and each change), then exits. Exits 1 when OUT holds no grade
or its files cannot be read (why is printed). No ROS, no sandbox, no root.
"""
import argparse
import os
import signal
import sys

from exam_lab.grader.publish import hand
from exam_lab.grader.publish.review import decisions, server
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.records import RecordError


def _stop(signum, frame):
    """SIGTERM stops the server as Ctrl-C does."""
    raise KeyboardInterrupt


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', required=True, help='the folder make grade wrote')
    parser.add_argument('--agreement', action='store_true', help='print the agreement with the proposals, then exit')
    args = parser.parse_args(argv)
    out = os.path.abspath(args.out)
    if args.agreement:
        try:
            state = decisions.load(os.path.join(out, decisions.FILE))
        except decisions.ReviewError as err:
            print('review: %s' % safe_text.clean(str(err)), file=sys.stderr)
            return 1
        print('agreement with the proposals (%s):' % os.path.join(out, decisions.FILE))
        for line in decisions.agreement_lines(state):
            print(line)
        return 0
    if not os.path.isdir(out):
        print('review: no grade.json in %s (no such folder): run make grade first' % out, file=sys.stderr)
        return 1
    try:
        review = server.Review(out)
    except (RecordError, hand.HandError, OSError) as err:
        print('review: %s' % safe_text.clean(str(err)), file=sys.stderr)
        return 1
    if not review.students:
        print('review: no grade.json in %s: run make grade first' % out, file=sys.stderr)
        return 1
    httpd = server.Server(review)
    signal.signal(signal.SIGTERM, _stop)
    # Ctrl-C stops it even when started with SIGINT ignored (a background job of a script, as `make
    # test` runs the grader's tests): Python installs no KeyboardInterrupt for an ignored SIGINT.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    for line in review.notes:
        print('note: %s' % safe_text.one_line(line))
    print('review of %d student(s): %s (Ctrl-C stops)' % (len(review.students), httpd.url), flush=True)
    try:
        httpd.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        httpd.server_close()
    print('review stopped: the points given are in %s' % os.path.join(out, hand.FILE), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
