#!/usr/bin/env bash
# `make report`: regenerates docs/report.md, docs/figures/{flight,dive,model_error}.png and docs/report.pdf
# from a live run of both drones (about 5 minutes). Every command output and number in the report comes
# from this run; the explanations are in lab/report/report_template.md.
# Usage: lab/report/report.sh [--render-only]   (--render-only redraws from the last run's bags and outputs)
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
# pandoc and weasyprint turn the Markdown into the PDF; pdftoppm is how its pages are checked.
"$repo/tools/install_deps.sh" pandoc weasyprint poppler-utils python3-rosmsg python3-rosparam
# install_deps.sh installs nothing where ROS comes from /opt/ros (Ubuntu + Noetic): say what is missing.
for tool in pandoc weasyprint pdfinfo; do
  command -v "$tool" >/dev/null || { echo "report: $tool is missing: apt-get install pandoc weasyprint poppler-utils" >&2; exit 1; }
done
source "$repo/tools/env.sh"
work="$EXAM_WS/report"
mkdir -p "$work"

if [ "${1:-}" != "--render-only" ]; then
  run_dir="$(mktemp -d /tmp/exam-report.XXXXXX)"
  # Whatever happens, end every process this run started (they carry its folder in their environment).
  trap '/usr/bin/python3 -m exam_lab.harness.supervisor --cleanup "$run_dir"; rm -rf "$run_dir"' EXIT
  /usr/bin/python3 "$repo/lab/report/collect.py" --work "$work" --run-dir "$run_dir"
fi
/usr/bin/python3 "$repo/lab/report/render.py" --work "$work" --repo "$repo"

# Figures and CSS are embedded (self-contained HTML), so the PDF does not depend on the current folder.
# weasyprint reads the HTML from stdin with no base URL (`--base-url ""`), so the links stay as report.md has them,
# relative (architecture.md, simple_answer/exam): they work from the PDF's place in the repository,
# where a base URL would turn each into a file:// path of the machine that built it.
cd "$repo/docs"
pandoc report.md --from gfm --to html5 --standalone --self-contained --resource-path=. \
  --metadata pagetitle="Model report: the ROS exam, mydrone and submarinedrone" \
  --css "$repo/lab/report/report.css" 2> "$work/pandoc.log" \
  | weasyprint --base-url "" - report.pdf 2>> "$work/pandoc.log" \
  || { cat "$work/pandoc.log" >&2; exit 1; }
if grep -a -q 'URI (file:' report.pdf; then
  echo "report: docs/report.pdf links to file:// paths of this machine" >&2
  exit 1
fi
echo "report: docs/report.pdf written ($(pdfinfo report.pdf | awk '/^Pages:/ {print $2}') pages)"
