"""Headless Chromium driven as a person uses it: the DevTools protocol over ``--remote-debugging-pipe``
(JSON messages ending in a NUL byte on file descriptors 3 and 4: the standard library is enough, no
websocket). A page is opened, a link or button clicked with the mouse at its place on the screen, text
typed at the keyboard's focus, and what the browser logged (console messages, a refused load, a
policy's violation) collected. test_page_browser.py's CHROMIUM is the browser, started with its flags.
"""
import json
import os
import select
import subprocess
import time

from test_page_browser import CHROMIUM


class BrowserError(Exception):
    pass


class Browser(object):
    """One headless Chromium with a profile in ``profile`` (a folder of the test's)."""

    def __init__(self, profile, timeout=60.0):
        self.timeout, self.events, self.next_id, self.buffer = timeout, [], 0, b''
        browser_in, self._to_browser = os.pipe()
        self._from_browser, browser_out = os.pipe()

        def pipes():  # in the child: the two ends on 3 and 4, inheritable
            a, b = os.dup(browser_in), os.dup(browser_out)
            os.dup2(a, 3)
            os.dup2(b, 4)
            os.set_inheritable(3, True)
            os.set_inheritable(4, True)
        self.log = open(os.path.join(profile, 'chromium.log'), 'w')
        self.process = subprocess.Popen(
            [CHROMIUM, '--headless', '--no-sandbox', '--disable-gpu', '--no-first-run', '--remote-debugging-pipe',
             '--window-size=1280,1000', '--user-data-dir=%s' % os.path.join(profile, 'profile'), 'about:blank'],
            preexec_fn=pipes, close_fds=False, stdout=self.log, stderr=subprocess.STDOUT)
        os.close(browser_in)
        os.close(browser_out)
        self.session = None

    def _receive(self, deadline):
        while b'\0' not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_browser], [], [], left)[0]:
                raise BrowserError('no answer from the browser in time')
            data = os.read(self._from_browser, 1 << 20)
            if not data:
                raise BrowserError('the browser closed its pipe (exit %s)' % self.process.poll())
            self.buffer += data
        message, self.buffer = self.buffer.split(b'\0', 1)
        return json.loads(message.decode('utf-8'))

    def call(self, method, params=None, session=True):
        self.next_id += 1
        message = {'id': self.next_id, 'method': method, 'params': params or {}}
        if session and self.session:
            message['sessionId'] = self.session
        os.write(self._to_browser, json.dumps(message).encode('utf-8') + b'\0')
        deadline = time.monotonic() + self.timeout
        while True:
            answer = self._receive(deadline)
            if answer.get('id') == self.next_id:
                if 'error' in answer:
                    raise BrowserError('%s: %s' % (method, answer['error']))
                return answer.get('result', {})
            self.events.append(answer)

    def wait_event(self, method, since):
        """The first event ``method`` from ``since`` (an index into ``events``) on."""
        deadline = time.monotonic() + self.timeout
        while True:
            for event in self.events[since:]:
                if event.get('method') == method:
                    return event
            self.events.append(self._receive(deadline))

    def open(self):
        """A new tab, its page, console and log watched."""
        target = self.call('Target.createTarget', {'url': 'about:blank'}, session=False)['targetId']
        self.session = self.call('Target.attachToTarget', {'targetId': target, 'flatten': True},
                                 session=False)['sessionId']
        for domain in ('Page', 'Runtime', 'Log', 'Network'):
            self.call(domain + '.enable')

    def go(self, url):
        """Open ``url`` as typed in the address bar; the main answer's status once loaded."""
        since = len(self.events)
        self.call('Page.navigate', {'url': url})
        return self._loaded(since)

    def reload(self):
        since = len(self.events)
        self.call('Page.reload')
        return self._loaded(since)

    def _loaded(self, since):
        self.wait_event('Page.loadEventFired', since)
        statuses = [e['params']['response']['status'] for e in self.events[since:]
                    if e.get('method') == 'Network.responseReceived' and e['params'].get('type') == 'Document']
        return statuses[-1] if statuses else None

    def evaluate(self, expression):
        result = self.call('Runtime.evaluate', {'expression': expression, 'returnByValue': True})
        if 'exceptionDetails' in result:
            raise BrowserError('%s: %s' % (expression, result['exceptionDetails']))
        return result['result'].get('value')

    def click(self, selector, navigates=True):
        """A mouse click at the middle of the element ``selector`` (scrolled into view first); the status
        of the page it leads to, once loaded, when it ``navigates``."""
        box = self.evaluate('(function () { var e = document.querySelector(%s); if (!e) return null; '
                            'e.scrollIntoView({block: "center"}); var r = e.getBoundingClientRect(); '
                            'return [r.left + r.width / 2, r.top + r.height / 2]; })()' % json.dumps(selector))
        if box is None:
            raise BrowserError('nothing on the page is %s' % selector)
        since = len(self.events)
        for kind in ('mouseMoved', 'mousePressed', 'mouseReleased'):
            self.call('Input.dispatchMouseEvent', {'type': kind, 'x': box[0], 'y': box[1], 'button': 'left',
                                                   'clickCount': 1 if kind != 'mouseMoved' else 0})
        return self._loaded(since) if navigates else None

    def type_into(self, selector, text):
        """Click into the field ``selector``, select what it holds, type ``text`` over it."""
        self.click(selector, navigates=False)
        self.evaluate('document.querySelector(%s).select()' % json.dumps(selector))
        self.call('Input.insertText', {'text': text})

    def logged(self, since=0):
        """What the pages logged from ``since`` (an index into ``events``) on: console calls, log entries
        (a refused load with its URL, a policy's violation), exceptions."""
        found = []
        for event in self.events[since:]:
            if event.get('method') == 'Runtime.consoleAPICalled':
                found.append('console: %s' % [a.get('value') for a in event['params'].get('args', [])])
            elif event.get('method') == 'Log.entryAdded':
                entry = event['params']['entry']
                found.append('log: %s %s' % (entry.get('text'), entry.get('url', '')))
            elif event.get('method') == 'Runtime.exceptionThrown':
                found.append('exception: %s' % event['params'])
        return found

    def close(self):
        try:
            self.call('Browser.close', session=False)
        except (BrowserError, OSError):
            pass
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(30)
        for fd in (self._to_browser, self._from_browser):
            os.close(fd)
        self.log.close()
