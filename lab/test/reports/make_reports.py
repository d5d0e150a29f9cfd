#!/usr/bin/env python3
"""Make the report fixtures (lab/test/unit/data/reports/) with the tools students use. Run as root or not:

    source tools/env.sh && python3 lab/test/reports/make_reports.py [--out DIR]

- **Real outputs.** A roscore on a free port of loopback, the project's own drones (``rosrun mydrone
  mydrone_node.py``, ``rosrun submarinedrone submarine_drone_node.py``), and the commands of questions
  4 to 8 run against them (``rosnode list``, ``rosnode info``, ``rostopic list``, ``rostopic type``,
  ``rosmsg info``, ``rostopic echo -n 3``, ``rostopic hz``): their outputs are pasted into the reports.
- **Real terminal screenshots.** The same commands in an xterm under Xvfb (light on dark, as a
  terminal is, and one dark on light), captured with ImageMagick's ``import -window``.
- **Real documents.** Each report is written as HTML (the screenshots embedded) and converted by
  LibreOffice headless to .odt or .docx, then to PDF, as a student's word processor exports it:
  French, in order, answers as text and screenshots (``fr_odt``); English, the sheet 001's answers in
  a table, out of order, question 6 missing (``en_docx_table``, also handed in as the .docx itself);
  a hostile one, question 4 missing, whose answer to question 5 is markup that would run a script if a
  page showed it unescaped (``hostile``: the review page's test).
- **Made from them.** An image-only scan (the French report's pages rendered, turned a little,
  noise added, saved as a PDF by PIL), an encrypted PDF (LibreOffice's export with a password), a
  broken one (the French PDF cut short, as an interrupted upload is), one of 45 pages (LibreOffice),
  a picture handed in (the dark-on-light screenshot) and a picture bomb (a PNG of 30000 x 30000
  pixels, a few kB).

``expected.json`` lists what a test must find in each, and on which page. Needs Xvfb, xterm and
ImageMagick (fixtures only: the grader itself needs none of them), poppler, LibreOffice, PIL, ROS.
"""
import argparse
import base64
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), 'src'))
from exam_lab.harness.supervisor import free_port  # noqa: E402 (the lab's harness, from its source)
from exam_lab.harness.wait import wait_until  # noqa: E402

DEFAULT_OUT = os.path.join(os.path.dirname(HERE), 'unit', 'data', 'reports')
PROMPT = '\033[1;32mstudent@vm\033[0m:\033[1;34m~/catkin_ws\033[0m$ '


def wait_for(check, timeout, what):
    """Wait until ``check`` holds (the harness's wait: an event the tools give no other way to wait for)."""
    if wait_until(check, timeout, period=0.2) is None:
        raise RuntimeError('timed out waiting for %s' % what)


class Ros(object):
    """A roscore and one drone node on a free port of loopback, for as long as the ``with`` lasts."""

    def __init__(self, package, node, topic):
        self.package, self.node, self.topic = package, node, topic
        self.env = dict(os.environ, ROS_MASTER_URI='http://127.0.0.1:%d' % free_port(), ROS_HOSTNAME='127.0.0.1',
                        ROS_HOME=tempfile.mkdtemp(prefix='reports-ros-'))
        self.processes = []

    def start(self, argv):
        self.processes.append(subprocess.Popen(argv, env=self.env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                               start_new_session=True))

    def __enter__(self):
        port = self.env['ROS_MASTER_URI'].rsplit(':', 1)[1]
        self.start(['roscore', '-p', port])
        wait_for(lambda: self.run(['rosnode', 'list'], check=False)[0] == 0, 60, 'the master')
        self.start(['rosrun', self.package, self.node])
        wait_for(lambda: self.topic in self.run(['rostopic', 'list'], check=False)[1], 60, 'the drone\'s topics')
        wait_for(lambda: 'data:' in self.run(['rostopic', 'echo', '-n', '1', self.topic], check=False, timeout=10)[1],
                 60, 'a message on %s' % self.topic)
        return self

    def run(self, argv, check=True, timeout=30):
        """``(status, output)`` of a command run against this master."""
        try:
            done = subprocess.run(argv, env=self.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        except subprocess.TimeoutExpired as err:
            return 124, (err.output or b'').decode('utf-8', 'replace')
        if check and done.returncode != 0:
            raise RuntimeError('%s failed: %s' % (' '.join(argv), done.stdout.decode()))
        return done.returncode, done.stdout.decode('utf-8', 'replace')

    def __exit__(self, *exc):
        for process in reversed(self.processes):
            try:
                os.killpg(process.pid, signal.SIGINT)
                process.wait(timeout=20)
            except (OSError, subprocess.TimeoutExpired):
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
        shutil.rmtree(self.env['ROS_HOME'], ignore_errors=True)


class Screen(object):
    """An X server of its own (Xvfb) to take xterm's screenshots on."""

    def __enter__(self):
        self.display = ':%d' % (80 + os.getpid() % 100)
        self.server = subprocess.Popen(['Xvfb', self.display, '-screen', '0', '1280x900x24', '-nolisten', 'tcp'],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        wait_for(lambda: subprocess.run(['xwininfo', '-display', self.display, '-root'], stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL).returncode == 0, 30, 'Xvfb')
        return self

    def __exit__(self, *exc):
        os.killpg(self.server.pid, signal.SIGTERM)
        self.server.wait()

    def shot(self, ros, commands, path, dark=True, columns=84, rows=None):
        """Run ``commands`` (shell lines) in an xterm against ``ros``'s master, each after the prompt, and
        save the window's screenshot once they are done (the window drawn the same twice)."""
        marker = tempfile.mktemp(prefix='reports-done-')
        title = 'reports-%d' % random.randrange(1 << 30)
        script = ''.join("printf '%%s%%s\\n' '%s' %s; %s; " % (PROMPT, _quoted(c), c) for c in commands)
        script += "printf '%%s' '%s'; touch %s; sleep 600" % (PROMPT, marker)
        colours = ['-bg', '#300a24', '-fg', '#eeeeec'] if dark else ['-bg', 'white', '-fg', 'black']
        rows = rows or 2 + sum(_lines(ros, c) for c in commands)
        xterm = subprocess.Popen(['xterm', '-display', self.display, '-T', title, '-geometry', '%dx%d+0+0' % (columns, rows),
                                  '-fa', 'DejaVu Sans Mono', '-fs', '11', '+sb', '-bw', '0'] + colours + ['-e', 'bash', '-c', script],
                                 env=ros.env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            wait_for(lambda: os.path.exists(marker), 90, 'the commands in xterm')
            window = None
            for line in subprocess.run(['xwininfo', '-display', self.display, '-name', title], stdout=subprocess.PIPE,
                                       check=True).stdout.decode().splitlines():
                if 'Window id:' in line:
                    window = line.split('Window id:')[1].split()[0]
            previous = None
            for _ in range(50):
                subprocess.run(['import', '-display', self.display, '-window', window, path], check=True)
                with open(path, 'rb') as f:
                    data = f.read()
                if data == previous:
                    break
                previous = data
                time.sleep(0.2)
        finally:
            os.killpg(xterm.pid, signal.SIGKILL)
            xterm.wait()
            if os.path.exists(marker):
                os.unlink(marker)


def _quoted(command):
    return "'%s'" % command.replace("'", "'\\''")


def _lines(ros, command):
    """How many lines a command prints (run once first): the terminal is made that tall."""
    return 1 + ros.run(['bash', '-c', command], check=False)[1].count('\n')


def outputs(ros, commands):
    """``{command: its real output}``."""
    return {c: ros.run(['bash', '-c', c], check=False)[1].rstrip('\n') for c in commands}


def image_tag(path, width_cm=15):
    with open(path, 'rb') as f:
        data = base64.b64encode(f.read()).decode()
    from PIL import Image
    with Image.open(path) as im:
        w, h = im.size
    return '<p><img src="data:image/png;base64,%s" width="%d" height="%d"></p>' % (data, int(width_cm * 37.8),
                                                                                int(width_cm * 37.8 * h / w))


def pre(text):
    escaped = text.replace('&', '&amp;').replace('<', '&lt;').replace('>', '&gt;')
    return '<pre style="font-family: DejaVu Sans Mono; font-size: 9pt">%s</pre>' % escaped


def html(title, body):
    return ('<!DOCTYPE html><html><head><meta charset="utf-8"><title>%s</title></head><body>'
            '<h1>%s</h1>%s</body></html>' % (title, title, body))


def soffice(args, cwd, profile):
    subprocess.run(['soffice', '--headless', '--norestore', '-env:UserInstallation=file://%s' % profile] + args, cwd=cwd,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=180)


def convert(html_path, kind, profile, pdf_options=''):
    """The HTML made a .odt or .docx (Writer's import), then a PDF of that: both paths returned."""
    folder, stem = os.path.dirname(html_path), os.path.splitext(os.path.basename(html_path))[0]
    target = {'odt': 'odt', 'docx': 'docx:MS Word 2007 XML'}[kind]
    soffice(['--infilter=HTML (StarWriter)', '--convert-to', target, os.path.basename(html_path)], folder, profile)
    document = os.path.join(folder, '%s.%s' % (stem, kind))
    pdf_dir = os.path.join(folder, 'pdf-' + stem)
    soffice(['--convert-to', 'pdf' + pdf_options, '--outdir', pdf_dir, document], folder, profile)
    return document, os.path.join(pdf_dir, stem + '.pdf')


def scan(pdf, target, dpi=120, angle=0.8, pages=None, seed=47):
    """An image-only 'scan' of ``pdf``: its pages rendered gray (``pdftoppm``), turned by ``angle``
    degrees, speckled, saved as one PDF of JPEG pages by PIL (``pages``: which, repeated if needed)."""
    from PIL import Image, ImageFilter
    folder = tempfile.mkdtemp(prefix='reports-scan-')
    try:
        subprocess.run(['pdftoppm', '-gray', '-r', str(dpi), '-png', pdf, os.path.join(folder, 'p')], check=True)
        names = sorted(n for n in os.listdir(folder) if n.endswith('.png'))
        chosen = [names[i % len(names)] for i in (pages or range(len(names)))]
        rng = random.Random(seed)
        images = []
        for name in chosen:
            im = Image.open(os.path.join(folder, name)).convert('L')
            im = im.rotate(angle, resample=Image.BICUBIC, expand=False, fillcolor=255)
            pixels = im.load()
            for _ in range(im.size[0] * im.size[1] // 400):
                pixels[rng.randrange(im.size[0]), rng.randrange(im.size[1])] = rng.choice((0, 90, 160))
            images.append(im.filter(ImageFilter.GaussianBlur(0.4)))
        images[0].save(target, 'PDF', resolution=dpi, save_all=True, append_images=images[1:], quality=70)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


AERIAL = ['rosnode list', 'rosnode info /mydrone', 'rostopic list', 'rostopic type /temperature',
          'rosmsg info std_msgs/Float32', 'rostopic echo -n 3 /temperature', 'timeout -s INT 6 rostopic hz /temperature']
SUBMARINE = ['rosnode list', 'rosnode info /submarine_drone', 'rostopic type /pressure_robot',
             'rosmsg info std_msgs/Float32', 'rostopic echo -n 3 /pressure_robot',
             'timeout -s INT 6 rostopic hz /pressure_robot', 'rostopic echo -n 3 /pressure_remote',
             'timeout -s INT 4 rostopic hz /pressure_remote']


def french_report(out, shots):
    """Sheet 000 (aerial), in French, questions 4 to 9 in order; outputs pasted, two screenshots."""
    body = ''.join([
        '<p>Étudiant : Jeanne Martin. Examen ROS, drone aérien (mydrone).</p>',
        '<h2>Question 4</h2><p>On lance le nœud avec <code>rosrun mydrone mydrone_node.py</code> puis on liste '
        'les nœuds :</p>', pre('$ rosnode list\n' + out['rosnode list']),
        '<p>Deux nœuds tournent : /mydrone, le drone, et /rosout, le nœud de log lancé par roscore avec le master.</p>',
        '<h2>Question 5</h2>', pre('$ rosnode info /mydrone\n' + out['rosnode info /mydrone']),
        '<p>Node [/mydrone] est le nom du nœud. Publications : les topics sur lesquels il publie, avec leur type. '
        'Subscriptions : aucun abonnement. Services : les services qu\'il offre (/altitude_warning). '
        '« contacting node » donne l\'adresse et le port du nœud, Pid est le numéro du processus. La connexion '
        'est sortante (outbound) vers /rosout, en TCPROS, le protocole TCP de ROS.</p>',
        '<h2>Question 6</h2>', pre('$ rostopic list\n' + out['rostopic list']),
        '<p>Le topic /rosout sert aux nœuds à publier leurs messages de log de manière centralisée : le nœud '
        'rosout les reçoit et les republie sur /rosout_agg.</p>',
        '<h2>Question 7</h2>', image_tag(shots['type']),
        '<p>Le message est du type std_msgs/Float32 : un seul champ float32 data qui contient la température.</p>',
        '<h2>Question 8</h2>', pre('$ rostopic echo -n 3 /temperature\n' + out['rostopic echo -n 3 /temperature']),
        image_tag(shots['hz_temperature']),
        '<p>Les messages sont publiés à 0.778 Hz environ (une période de 1.285 s).</p>',
        '<h2>Question 9</h2>', pre('$ cd ~/catkin_ws/src\n$ catkin_create_pkg exam rospy std_msgs mydrone'),
        '<p>La commande crée le paquet exam avec ses dépendances rospy, std_msgs et mydrone (package.xml et '
        'CMakeLists.txt).</p>'])
    return html('Rapport d\'examen ROS', body)


def english_table_report(out, shots):
    """Sheet 001 (underwater), in English, its answers in a table, out of order, question 6 missing."""
    def cell(text):  # pasted into a cell as lines of a monospace font, which wrap as a word processor's do
        # a line longer than the cell is broken where the cell ends (rosnode info's row of 80 dashes)
        text = '\n'.join(line[i:i + 56] for line in text.split('\n') for i in range(0, max(1, len(line)), 56))
        escaped = text.replace('&', '&amp;').replace('<', '&lt;').replace('>', '&gt;').replace('\n', '<br>')
        return '<p style="font-family: DejaVu Sans Mono; font-size: 7pt">%s</p>' % escaped if text else ''

    def row(q, command, output, comment):
        return ('<tr><td width="45">%s</td><td width="110">%s</td><td width="280">%s</td><td width="185">%s</td></tr>'
                % (q, command, cell(output), comment))
    rows = [
        row('Q7', '<code>rostopic type /pressure_robot</code>', out['rostopic type /pressure_robot'] + '\n' +
            out['rosmsg info std_msgs/Float32'],
            'The type is std_msgs/Float32: one field, float32 data, the pressure in Pa.'),
        row('Q4', '<code>rosnode list</code>', out['rosnode list'],
            'Two nodes: the drone /submarine_drone and /rosout, started by roscore.'),
        row('Q5', '<code>rosnode info /submarine_drone</code>', out['rosnode info /submarine_drone'],
            'Its publications, no subscriptions, its services; contacting node gives its address and port, Pid its '
            'process number; the connection is outbound to /rosout over TCPROS.'),
        row('Q9', '<code>catkin_create_pkg exam rospy std_msgs submarinedrone</code>', '',
            'Creates the package exam depending on rospy, std_msgs and submarinedrone.'),
        row('Q8', '<code>rostopic echo -n 3 /pressure_robot</code>, <code>rostopic hz /pressure_robot</code>',
            out['rostopic echo -n 3 /pressure_robot'] + '\n' + out['timeout -s INT 6 rostopic hz /pressure_robot'],
            'The robot\'s pressure is published at 2 Hz. The remote pressure (screenshot below) at 1 Hz.'),
    ]
    table = ('<table width="620" border="1" cellpadding="3"><tr><th>Question</th><th>Command</th><th>Output</th>'
             '<th>Comment</th></tr>%s</table>' % ''.join(rows))
    body = ('<p>Student: John Smith. ROS exam, underwater drone (submarinedrone).</p>' + table +
            '<p>Remote pressure:</p>' + image_tag(shots['remote']))
    return html('ROS exam report', body)


#: A student's answer that runs a script, loads a picture or opens a local file if shown unescaped; one
#: element a line (no line wraps in the PDF, so its text comes back as typed).
HOSTILE_LINES = ('<script>document.title="pwned"</script>', '<img src=x onerror="document.title=\'pwned\'">',
                 '<a href="file:///etc/passwd">x</a>')


def hostile_report(out):
    """Sheet 000 (aerial), in French, question 4 missing; question 5's comment is :data:`HOSTILE_LINES`."""
    body = ''.join([
        '<p>Étudiant : Mallory Script. Examen ROS, drone aérien (mydrone).</p>',
        '<h2>Question 5</h2>', pre('$ rosnode info /mydrone\n' + out['rosnode info /mydrone']),
        '<p>Voici ce que le nœud affiche, expliqué ci-dessous :</p>', pre('\n'.join(HOSTILE_LINES)),
        '<h2>Question 6</h2>', pre('$ rostopic list\n' + out['rostopic list']),
        '<p>Le topic /rosout reçoit les messages de log de tous les nœuds.</p>'])
    return html('Rapport d\'examen ROS', body)


def long_report(pages):
    body = ''.join('<p style="page-break-before: always">Page %d. Annexe : sortie de rostopic echo.</p>' % (n + 1)
                   for n in range(pages))
    return html('Annexes', body)


def make_hostile(aerial, out, work, profile):
    """``out/hostile.pdf``: :func:`hostile_report` of the aerial drone's outputs, through LibreOffice's .odt."""
    with open(os.path.join(work, 'hostile.html'), 'w') as f:
        f.write(hostile_report(aerial))
    _, pdf = convert(os.path.join(work, 'hostile.html'), 'odt', profile)
    shutil.copyfile(pdf, os.path.join(out, 'hostile.pdf'))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', default=DEFAULT_OUT)
    parser.add_argument('--only-hostile', action='store_true', help='make hostile.pdf alone, from the drone\'s outputs in '
                        'outputs.json kept in OUT (no ROS, no X: the other fixtures stay as they are)')
    args = parser.parse_args(argv)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    work = tempfile.mkdtemp(prefix='reports-make-')
    profile = os.path.join(work, 'lo-profile')
    if args.only_hostile:
        try:
            with open(os.path.join(out, 'outputs.json')) as f:
                make_hostile(json.load(f)['aerial'], out, work, profile)
        finally:
            shutil.rmtree(work, ignore_errors=True)
        return 0
    try:
        shots = {}
        with Screen() as screen:
            with Ros('mydrone', 'mydrone_node.py', '/temperature') as ros:
                aerial = outputs(ros, AERIAL)
                shots['type'] = os.path.join(work, 'type.png')
                screen.shot(ros, ['rostopic type /temperature', 'rosmsg info std_msgs/Float32'], shots['type'])
                shots['hz_temperature'] = os.path.join(work, 'hz_temperature.png')
                screen.shot(ros, ['timeout -s INT 6 rostopic hz /temperature'], shots['hz_temperature'])
                shots['rosnode'] = os.path.join(out, 'screenshot_rosnode_list.png')
                screen.shot(ros, ['rosnode list', 'rostopic list'], shots['rosnode'], dark=False, columns=60)
            with Ros('submarinedrone', 'submarine_drone_node.py', '/pressure_remote') as ros:
                submarine = outputs(ros, SUBMARINE)
                shots['remote'] = os.path.join(work, 'remote.png')
                screen.shot(ros, ['rostopic echo -n 3 /pressure_remote', 'timeout -s INT 4 rostopic hz /pressure_remote'],
                            shots['remote'])
        for name, text in (('fr_odt', french_report(aerial, shots)), ('en_docx_table', english_table_report(submarine, shots)),
                           ('encrypted', french_report(aerial, shots)), ('long', long_report(45))):
            with open(os.path.join(work, name + '.html'), 'w') as f:
                f.write(text)
        odt, fr_pdf = convert(os.path.join(work, 'fr_odt.html'), 'odt', profile)
        docx, en_pdf = convert(os.path.join(work, 'en_docx_table.html'), 'docx', profile)
        _, long_pdf = convert(os.path.join(work, 'long.html'), 'odt', profile)
        encrypted = '{"EncryptFile":{"type":"boolean","value":"true"},"DocumentOpenPassword":{"type":"string","value":"exam"}}'
        _, encrypted_pdf = convert(os.path.join(work, 'encrypted.html'), 'odt', profile, ':writer_pdf_Export:' + encrypted)
        for source, name in ((fr_pdf, 'fr_odt.pdf'), (odt, 'fr_odt.odt'), (en_pdf, 'en_docx_table.pdf'),
                             (docx, 'en_docx_table.docx'), (long_pdf, 'long_45_pages.pdf')):
            shutil.copyfile(source, os.path.join(out, name))
        shutil.copyfile(encrypted_pdf, os.path.join(out, 'encrypted.pdf'))
        make_hostile(aerial, out, work, profile)
        with open(fr_pdf, 'rb') as f:
            data = f.read()
        with open(os.path.join(out, 'broken.pdf'), 'wb') as f:
            f.write(data[:len(data) * 6 // 10])  # an upload cut short
        scan(fr_pdf, os.path.join(out, 'scan.pdf'))
        from PIL import Image
        Image.new('1', (30000, 30000), 1).save(os.path.join(out, 'picture_bomb.png'), optimize=True)
        with open(os.path.join(out, 'outputs.json'), 'w') as f:
            json.dump({'aerial': aerial, 'submarine': submarine}, f, indent=1, sort_keys=True, ensure_ascii=False)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    for name in sorted(os.listdir(out)):
        print('%-28s %8d bytes' % (name, os.path.getsize(os.path.join(out, name))))
    return 0


if __name__ == '__main__':
    sys.exit(main())
