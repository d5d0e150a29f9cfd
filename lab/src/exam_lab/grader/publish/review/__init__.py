"""``make review OUT=<dir>``: the teacher's one pass over a class's 13 hand points, in a browser.

The machine judges 17 of the 30 points; the report's questions 4 to 9, the comments and the code
quality are the teacher's (``hand.csv``). ``make grade`` proposes each of them with its evidence
(``proposals.csv``, ``<student>/proposals.json``) beside each student's report (``report.json``, its
page images) and code (``<student>/code/``). The review page shows, for each item, the class's answers
in groups of identical ones (:mod:`.groups`): the teacher confirms or changes a group's points once;
and, for each student, every proposal beside the report's pages and the code, to confirm or change
one by one. Each decision is written into hand.csv and kept in review.json with the proposal it was
made on (:mod:`.decisions`), so the agreement with the proposals is reported per item; no proposal
is a point until the teacher confirms it.

Layers: :mod:`.groups` (pure), :mod:`.folder` (what is read of OUT, safely), :mod:`.decisions`
(hand.csv and review.json), :mod:`.page` (HTML, no script), :mod:`.server` (http.server on 127.0.0.1
with a token).
"""
