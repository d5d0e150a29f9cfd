# Two commands on a fresh Debian 12 machine:  make run  |  make test
# Every target installs what is missing (Debian's ROS 1 packages) and builds the workspace in .ws/ first.
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
.DEFAULT_GOAL := help

ENV := source tools/env.sh
# `make test TESTS=run_tests_exam` runs one catkin test target instead of all of them.
TESTS ?= run_tests
# make test-unit: every package's pytest unit tests (catkin names them run_tests_<package>_pytest_unit;
# each package folder is named as its package, but lab/ holds exam_lab) and lab's docs checks.
UNIT_TESTS := run_tests_exam_lab_pytest_unit run_tests_exam_lab_pytest_docs \
	$(patsubst %/test/unit,run_tests_%_pytest_unit,$(filter-out lab/test/unit,$(wildcard */test/unit)))

.PHONY: help deps build run run-submarine run-simple test test-unit test-grader report bench soak mutation fairness grade rescore review worksheet check clean

help:
	@echo "make run            install, build, and run the aerial drone with the exam node (Ctrl-C stops)"
	@echo "make run-submarine  the same with the underwater drone"
	@echo "make run-simple [SHEET=altitude|depth]  the simple answer of docs/report.md, built on its own"
	@echo "make test           install, build, and run every unit and rostest test"
	@echo "make test-unit      the pytest unit and docs tests only (seconds, no ROS master)"
	@echo "make test-grader    the grader's tests only (lab/test/grader: classes graded by running, root)"
	@echo "make report         regenerate docs/ (command outputs, figures, PDF) from a live run"
	@echo "make bench          benchmarks of the exam node against the naive baseline"
	@echo "make soak           30-minute soak run, checked offline against the debounce rule"
	@echo "make mutation       mutation testing of the nodes' code against its tests (about 30 min)"
	@echo "make fairness [JOBS=n] [OUT=<dir>]  the grader on generated student answers (46 correct, 46 one-mistake,"
	@echo "                    both sheets) as one class; its report into docs/grading.md (about 30 min)"
	@echo "make grade SUBMISSION=<dir|zip> | CLASS=<dir|zip> [SHEET=altitude|depth] [OUT=<dir>] [JOBS=n]"
	@echo "                    [WORKSHEET=<Moodle grading worksheet.csv>] [ENGINE=local|slurm] [SLURM_ARGS='...']"
	@echo "                    grade students' exam packages by running them (docs/grading.md)"
	@echo "make rescore OUT=<dir> [WORKSHEET=...]  today's rubric on a run's kept measurements (seconds, no ROS)"
	@echo "make review OUT=<dir> [AGREEMENT=1]  the hand points of a class in one pass, on a page served to this"
	@echo "                    machine only (the URL it prints; Ctrl-C stops); AGREEMENT=1: the teacher against the proposals"
	@echo "make worksheet OUT=<dir> [WORKSHEET=<Moodle grading worksheet.csv>]"
	@echo "                    the whole grades (machine + OUT/hand.csv, scaled) into OUT/moodle-worksheet.csv"
	@echo "make check PACKAGE=<dir|zip> [SHEET=altitude|depth] [REPORT=<your report.pdf>]"
	@echo "                    a student's own check of their package, as an ordinary user (docs/grading.md)"
	@echo "make clean          remove the build workspace .ws/"

deps:
	@tools/install_deps.sh

build: deps
	@tools/build_ws.sh

# `make run ARGS='threshold:=1400 delay:=3'` passes launch arguments.
run: build
	@tools/run_launch.sh exam.launch $(ARGS)

run-submarine: build
	@tools/run_launch.sh exam_submarine.launch $(ARGS)

# `make run-simple [SHEET=altitude|depth] [ARGS='threshold:=1200']`: the simple answer (docs/simple_answer/exam),
# a second package named exam, in a workspace of its own (.ws/simple_answer).
run-simple: deps
	@docs/simple_answer/run.sh $(or $(SHEET),altitude) $(ARGS)

test: build
	@tools/run_tests.sh $(TESTS)

test-unit: build
	@tools/run_tests.sh $(UNIT_TESTS)

test-grader: build
	@tools/run_tests.sh run_tests_exam_lab_pytest_grader

report: build
	@lab/report/report.sh

bench: build
	@lab/bench/run.sh

soak: build
	@lab/soak/soak.sh

mutation: build
	@lab/mutation/run.sh

# make fairness [JOBS=n] [OUT=<dir>]: generated correct and one-mistake answers graded as one class (issue 35)
fairness: build
	@$(ENV) && exec python3 lab/scripts/fairness.py $(if $(OUT),--out "$(OUT)") $(if $(JOBS),--jobs "$(JOBS)")

# make grade SUBMISSION=<dir or zip> | CLASS=<dir or zip> [SHEET=altitude|depth] [OUT=<dir>] [JOBS=n]
#            [WORKSHEET=<Moodle's offline grading worksheet: kept in OUT, filled with the whole grades>]
#            [ENGINE=slurm: one Slurm array task per student] [SLURM_ARGS=<sbatch's options, e.g. --partition=x>]
grade: build
	@$(ENV) && exec python3 lab/scripts/grade.py \
	  $(if $(SUBMISSION),--submission "$(SUBMISSION)") $(if $(CLASS),--class "$(CLASS)") \
	  $(if $(SHEET),--sheet "$(SHEET)") $(if $(OUT),--out "$(OUT)") $(if $(JOBS),--jobs "$(JOBS)") \
	  $(if $(WORKSHEET),--worksheet "$(WORKSHEET)") \
	  $(if $(ENGINE),--engine "$(ENGINE)") $(if $(SLURM_ARGS),--slurm-args "$(SLURM_ARGS)")

# make rescore OUT=<make grade's OUT> [WORKSHEET=...]: today's rubric on the measurements the run kept
rescore: build
	@$(ENV) && exec python3 lab/scripts/rescore.py --out "$(OUT)" $(if $(WORKSHEET),--worksheet "$(WORKSHEET)")

# make review OUT=<make grade's OUT> [AGREEMENT=1]: the review page (127.0.0.1, a token in the URL it prints)
review: build
	@$(if $(OUT),,$(error make review needs OUT=<the folder make grade wrote>))
	@$(ENV) && exec python3 lab/scripts/review.py --out "$(OUT)" $(if $(AGREEMENT),--agreement)

# make worksheet OUT=<make grade's OUT> [WORKSHEET=<Moodle's worksheet; default: the one kept in OUT>]: the
# machine's and the hand points (OUT/hand.csv, filled by the teacher) as one grade on the worksheet's scale,
# into OUT/moodle-worksheet.csv, the file to upload
worksheet: build
	@$(ENV) && exec python3 lab/scripts/worksheet.py --out "$(OUT)" $(if $(WORKSHEET),--worksheet "$(WORKSHEET)")

# make check PACKAGE=<dir or zip> [SHEET=altitude|depth] [REPORT=<pdf>]: a student's own check, without root or sudo.
# It builds the workspace but installs nothing: a student's machine has ROS already, not the teacher's tools.
check:
	@$(if $(PACKAGE),,$(error make check needs PACKAGE=<your exam package: its folder or its zip>))
	@tools/build_ws.sh
	@$(ENV) && exec python3 lab/scripts/check.py --package "$(PACKAGE)" $(if $(SHEET),--sheet "$(SHEET)") \
	  $(if $(REPORT),--report "$(REPORT)")

clean:
	rm -rf .ws
