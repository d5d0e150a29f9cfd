#!/usr/bin/env bash
# Installs what the workspace needs, from Debian 12's own ROS 1 packages; skips what is already there.
# Usage: tools/install_deps.sh [extra Debian packages...]   (make calls it; safe to run again)
set -euo pipefail

# ROS Noetic from packages.ros.org (Ubuntu 20.04) lives in /opt/ros: nothing to install here,
# the README lists the ros-noetic-* names to install instead.
if [ -f /opt/ros/noetic/setup.bash ]; then
  exit 0
fi

packages=(
  ros-core-dev catkin python3-catkin-pkg
  python3-rospy python3-std-msgs python3-rostest python3-rostopic python3-rosservice
  python3-rosnode python3-roslaunch python3-rosbag rosbash
  python3-diagnostic-updater python3-diagnostic-msgs
  python3-pytest python3-hypothesis python3-matplotlib
  iproute2 bubblewrap
  # the teacher's page is tested in a headless browser; the similarity check has a venv of its own
  chromium python3-venv
  # the report's page limit is read from its PDF (pdftohtml) by the docs tests
  poppler-utils
  # students' reports are read in a box: the text layer (poppler), OCR of scans and screenshots
  # (tesseract, French and English), an .odt or .docx handed in instead of a PDF (LibreOffice headless)
  tesseract-ocr tesseract-ocr-fra tesseract-ocr-eng libreoffice-writer-nogui
  # class zips are tested as the usual tools make them (Info-ZIP, bsdtar, 7-Zip), in the locales they
  # run in (a UTF-8 one and a Latin-1 one, made by localedef from the locales package's sources)
  zip unzip libarchive-tools p7zip-full locales
  # the code-quality proposal's static check of the student's node (run in the inspection's box)
  python3-pyflakes
  # the report reader's pictures (screenshots prepared for OCR, page images) are PIL's
  python3-pil
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
# A first install takes minutes: say what and why, and let apt show its own progress (each download,
# each package unpacked and set up) rather than minutes of silence.
echo "install_deps: ${#missing[@]} Debian packages missing, installing them with apt-get (a first install"
echo "install_deps: of ROS takes a few minutes): ${missing[*]}"
$sudo apt-get update
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${missing[@]}"
echo "install_deps: done"
