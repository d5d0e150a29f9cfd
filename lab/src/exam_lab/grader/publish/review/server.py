"""The review page's server: the standard library's http.server on 127.0.0.1, a free port, one
random token. No rospy.

Only the teacher reaches it: it listens on the loopback address only; every path begins with a token
of 32 random bytes (``secrets``) printed once with the URL, and a request without it is a 404 that says
nothing; a ``Host`` header other than the server's own address is a 403, so that a web page which
makes its name point at 127.0.0.1 (DNS rebinding) reads nothing, and a post whose ``Origin`` or
``Sec-Fetch-Site`` says it comes from another site is a 403 too. What is served is the pages made
here and the page images report.json names below a student's folder, read without following a link
(:func:`~exam_lab.grader.publish.review.folder.read_inside`); no file by its path, no folder listed.
Every answer says ``no-store``, ``nosniff``, a referrer (the token) for this origin only (so a form's post
still carries its ``Origin``), and the page's policy (no script).

A post changes hand.csv (:mod:`~exam_lab.grader.publish.review.decisions`), one at a time under a
lock, then redirects (303) to the page it came from with what was done: a reload never posts again.
"""
import hmac
import http.server
import os
import re
import secrets
import socketserver
import threading
import urllib.parse

from exam_lab.grader.publish import hand
from exam_lab.grader.publish.review import decisions, folder, groups, page
from exam_lab.grader.score.sheets import HAND_ITEMS

#: A post's body at most (bytes): one form's fields.
BODY_CAP = 16 << 10
#: Messages kept for the redirects that show them (the oldest dropped).
MESSAGES = 200


class Review(object):
    """One OUT under review: its students (read once), and what changes (hand.csv, review.json), read at
    each request under the lock."""

    def __init__(self, out):
        self.out = os.path.realpath(out)
        self.title = 'Hand points: %s' % os.path.basename(self.out)
        self.students, self.notes = folder.load(self.out)
        self.records = [s.record for s in self.students]
        self.lock, self.said_lock = threading.Lock(), threading.Lock()
        self.messages = {}

    def _state(self):
        return decisions.load(os.path.join(self.out, decisions.FILE))

    def _cells(self):
        return decisions.cells_now(os.path.join(self.out, hand.FILE))

    def say(self, messages):
        key = secrets.token_urlsafe(8)
        with self.said_lock:
            self.messages[key] = messages
            while len(self.messages) > MESSAGES:
                self.messages.pop(next(iter(self.messages)))
        return key

    def groups(self, item):
        return groups.groups(item, [(s.sheet, s.proposals.get(item)) for s in self.students])

    # the pages

    def index(self, base, messages):
        with self.lock:
            state, cells = self._state(), self._cells()
        return page.index(self.title, base, self.students, cells, decisions.agreement(state), self.notes, messages)

    def item(self, base, item, messages):
        with self.lock:
            state, cells = self._state(), self._cells()
        found = self.groups(item)
        targets = {g.id: decisions.group_targets(g.id, item, [self.students[i] for i in g.members], cells, state)
                   for g in found}
        return page.item_page(self.title, base, item, found, self.students, cells, targets, messages)

    def student(self, base, index, messages):
        with self.lock:
            cells = self._cells()
        student = self.students[index]
        return page.student_page(self.title, base, student, cells, folder.code_files(student.folder), messages,
                                 len(self.students))

    # the decisions

    def give_group(self, item, group_id, text):
        """The group's points to each member without one (or still with this group's): messages."""
        try:
            value = decisions.parse_points(text, item)
        except ValueError as err:
            return [('problem', 'nothing written: %s' % err)]
        found = [g for g in self.groups(item) if g.id == group_id]
        if not found:
            return [('problem', 'that group is gone (the proposals changed): nothing written')]
        with self.lock:
            state, cells = self._state(), self._cells()
            write, kept = decisions.group_targets(group_id, item, [self.students[i] for i in found[0].members],
                                                  cells, state)
            done, left = decisions.give(self.out, self.records, state,
                                        [(s, item, value, was) for s, was in write], 'group', group_id)
        said = [('said', '%s: %s given to %d student(s): %s' % (item, hand.points_cell(value) or 'no point',
                                                               len(done), ', '.join(s.name for s in done)))]
        for student, cell in kept + left:
            said.append(('problem', '%s kept its %s (decided alone or typed in hand.csv): change it on its page'
                         % (student.name, cell)))
        return said

    def give_student(self, index, item, text, was):
        student = self.students[index]
        try:
            value = decisions.parse_points(text, item)
        except ValueError as err:
            return [('problem', 'nothing written: %s' % err)]
        with self.lock:
            done, left = decisions.give(self.out, self.records, self._state(), [(student, item, value, was)],
                                        'student')
        if left:
            return [('problem', '%s %s: hand.csv holds %s now (changed since the page was shown): nothing written; '
                                'see it and decide again' % (student.name, item, left[0][1] or 'nothing'))]
        return [('said', '%s %s: %s written to hand.csv' % (student.name, item, hand.points_cell(value) or 'emptied'))]


class Handler(http.server.BaseHTTPRequestHandler):
    server_version = 'exam-review'
    sys_version = ''
    timeout = 60

    def log_message(self, format, *args):  # the teacher's terminal: the URL (and its token) once, not per request
        pass

    # what comes in

    def _host_ok(self):
        port = self.server.server_address[1]
        host = self.headers.get('Host', '')
        return host in ('127.0.0.1:%d' % port, 'localhost:%d' % port)

    def _same_origin(self):
        port = self.server.server_address[1]
        origin = self.headers.get('Origin')
        if origin is not None and origin not in ('http://127.0.0.1:%d' % port, 'http://localhost:%d' % port):
            return False
        return self.headers.get('Sec-Fetch-Site', 'same-origin') in ('same-origin', 'none')

    def _route(self):
        """``(the base with the token, the rest, the query)``, or None without the token."""
        path, _, query = self.path.split('#', 1)[0].partition('?')  # the path as sent: no URL parser's host
        parts = path.split('/', 2)
        if len(parts) < 2 or parts[0] or not hmac.compare_digest(parts[1].encode('utf-8', 'replace'),
                                                                 self.server.token.encode('ascii')):
            return None
        return '/' + parts[1], '/' + (parts[2] if len(parts) > 2 else ''), urllib.parse.parse_qs(query)

    # what goes out

    def _send(self, status, body, kind='text/html; charset=utf-8', more=()):
        data = body.encode('utf-8') if isinstance(body, str) else body
        self.send_response(status)
        self.send_header('Content-Type', kind)
        self.send_header('Content-Length', str(len(data)))
        self.send_header('Content-Security-Policy', page.POLICY)
        self.send_header('X-Content-Type-Options', 'nosniff')
        self.send_header('X-Frame-Options', 'DENY')
        self.send_header('Referrer-Policy', 'same-origin')
        self.send_header('Cache-Control', 'no-store')
        for name, value in more:
            self.send_header(name, value)
        self.end_headers()
        if self.command != 'HEAD':
            self.wfile.write(data)

    def _refuse(self, status):
        self._send(status, {403: 'forbidden\n', 404: 'not found\n', 405: 'not allowed\n',
                            413: 'too large\n'}[status], 'text/plain; charset=utf-8')

    def do_GET(self):
        if not self._host_ok():
            return self._refuse(403)
        route = self._route()
        if route is None:
            return self._refuse(404)
        base, rest, query = route
        review = self.server.review
        messages = review.messages.get((query.get('said') or [''])[0], ())
        try:
            if rest == '/':
                return self._send(200, review.index(base, messages))
            found = re.match(r'^/item/([A-Za-z0-9]+)$', rest)
            if found and found.group(1) in HAND_ITEMS:
                return self._send(200, review.item(base, found.group(1), messages))
            found = re.match(r'^/student/(\d{1,6})$', rest)
            if found and int(found.group(1)) < len(review.students):
                return self._send(200, review.student(base, int(found.group(1)), messages))
            found = re.match(r'^/image/(\d{1,6})/(\d{1,6})$', rest)
            if found and int(found.group(1)) < len(review.students):
                try:
                    data = folder.page_image(review.students[int(found.group(1))], int(found.group(2)))
                except folder.Refused:
                    return self._refuse(404)
                return self._send(200, data, 'image/png')
        except (hand.HandError, decisions.ReviewError) as err:
            return self._send(200, page.problem(review.title, base, str(err)))
        return self._refuse(404)

    do_HEAD = do_GET

    def do_POST(self):
        if not self._host_ok() or not self._same_origin():
            return self._refuse(403)
        route = self._route()
        if route is None:
            return self._refuse(404)
        base, rest, _ = route
        review = self.server.review
        try:
            length = int(self.headers.get('Content-Length') or 0)
        except ValueError:
            return self._refuse(413)
        if not 0 <= length <= BODY_CAP:
            return self._refuse(413)
        form = urllib.parse.parse_qs(self.rfile.read(length).decode('utf-8', 'replace'), keep_blank_values=True)
        points, was = (form.get('points') or [''])[0], (form.get('was') or [''])[0]
        try:
            found = re.match(r'^/item/([A-Za-z0-9]+)/([0-9a-f]{12})$', rest)
            if found and found.group(1) in HAND_ITEMS:
                said = review.give_group(found.group(1), found.group(2), points)
                back = '%s/item/%s' % (base, found.group(1))
                anchor = '#group-' + found.group(2)
            else:
                found = re.match(r'^/student/(\d{1,6})/([A-Za-z0-9]+)$', rest)
                if not (found and int(found.group(1)) < len(review.students) and found.group(2) in HAND_ITEMS):
                    return self._refuse(404)
                said = review.give_student(int(found.group(1)), found.group(2), points, was)
                back = '%s/student/%s' % (base, found.group(1))
                anchor = '#item-' + found.group(2)
        except (hand.HandError, decisions.ReviewError, OSError) as err:
            said = [('problem', 'nothing written: %s' % err)]
            back, anchor = base + '/', ''
        self._send(303, 'see %s\n' % back, 'text/plain; charset=utf-8',
                   [('Location', '%s?said=%s%s' % (back, review.say(said), anchor))])

    def _not_allowed(self):
        self._refuse(405)

    do_PUT = do_DELETE = do_PATCH = do_OPTIONS = _not_allowed


class Server(socketserver.ThreadingMixIn, http.server.HTTPServer):
    daemon_threads = True

    def __init__(self, review, port=0):
        self.review = review
        self.token = secrets.token_urlsafe(32)
        http.server.HTTPServer.__init__(self, ('127.0.0.1', port), Handler)

    def server_bind(self):
        """Bound without HTTPServer's name lookup (``getfqdn``: a DNS query on a machine offline)."""
        socketserver.TCPServer.server_bind(self)
        self.server_name, self.server_port = self.server_address[:2]

    @property
    def url(self):
        return 'http://127.0.0.1:%d/%s/' % (self.server_address[1], self.token)
