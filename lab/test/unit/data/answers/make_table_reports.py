#!/usr/bin/env python3
"""Make the table reports of test_answers.py with the tool students use: LibreOffice headless.

    python3 lab/test/unit/data/answers/make_table_reports.py

Each report is an HTML page (a table: question, command, output, comment) converted by LibreOffice
headless to .odt, then to PDF, as a student's word processor exports it. The outputs pasted are the
drones' own (reference-altitude.json and reference-depth.json here, captured by
exam_lab.grader.host.reference); the comments are a student's sentences. ``table_middle``: the
cells centred on their row (HTML's default), French, out of order, question 8 missing;

``table_top``: the cells on their row's top, English, sheet 001, questions 6 and 9 missing. Both
have question 5's output, whose blank lines split its cell.
"""
import html
import json
import os
import shutil
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

ROWS = {
    'table_middle': ('altitude', 'middle', [
        ('Q6', 'rostopic_list', 'Le topic /rosout reçoit les messages de log de tous les nœuds.'),
        ('Q4', 'rosnode_list', 'Deux nœuds tournent : le drone et rosout, lancé avec le master.'),
        ('Q5', 'rosnode_info', 'Le nœud publie les capteurs, ne s\'abonne à rien et offre le service. '
                               'contacting node : son adresse et son port. Pid : son processus. La connexion '
                               'sortante (outbound) va vers rosout, en TCPROS, le protocole TCP de ROS.'),
        ('Q7', 'rosmsg_info', 'Le message contient un seul champ float32 nommé data.'),
        ('Q9', 'catkin_create_pkg', 'La commande crée le paquet exam et ses dépendances dans package.xml.'),
    ]),
    'table_top': ('depth', 'top', [
        ('Q4', 'rosnode_list', 'Two nodes run: the submarine drone and rosout, started by roscore.'),
        ('Q5', 'rosnode_info', 'It publishes the sensors, subscribes to nothing and offers its service.'),
        ('Q7', 'rostopic_type', 'The topic carries a standard message holding one float value.'),
        ('Q8', 'rostopic_echo', 'The robot pressure is published at 2 Hz, twice a second.'),
    ]),
}


def page(sheet, valign, rows):
    with open(os.path.join(HERE, 'reference-%s.json' % sheet)) as f:
        commands = json.load(f)['commands']
    cells = []
    for item, key, comment in rows:
        output = '<br>'.join(html.escape(line) for line in commands[key]['output'].splitlines())
        cells.append('<tr valign="%s"><td width="8%%">%s</td><td width="17%%">%s</td><td width="45%%"><font face="Liberation Mono" '
                     'size="1">%s</font></td><td width="30%%">%s</td></tr>' % (
                         valign, item, html.escape(commands[key]['line']), output, html.escape(comment)))
    return ('<html><head><meta charset="utf-8"></head><body><h1>ROS exam report</h1>'
            '<table border="1" width="100%%"><tr><th>Question</th><th>Command</th><th>Output</th><th>Comment</th></tr>'
            '%s</table></body></html>' % ''.join(cells))


def main():
    work = tempfile.mkdtemp(prefix='answers-tables-')
    try:
        for name, (sheet, valign, rows) in ROWS.items():
            source = os.path.join(work, name + '.html')
            with open(source, 'w') as f:
                f.write(page(sheet, valign, rows))
            env = dict(os.environ, HOME=work)
            subprocess.run(['soffice', '--headless', '--convert-to', 'odt:writer8', '--outdir', work, source],
                           check=True, env=env, stdout=subprocess.DEVNULL)
            subprocess.run(['soffice', '--headless', '--convert-to', 'pdf', '--outdir', work,
                            os.path.join(work, name + '.odt')], check=True, env=env, stdout=subprocess.DEVNULL)
            shutil.copy(os.path.join(work, name + '.pdf'), os.path.join(HERE, name + '.pdf'))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == '__main__':
    main()
