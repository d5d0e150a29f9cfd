# Hostile: in the grader's check of the launch file as handed in (its command line names roslaunch's
# loader), say what an accepted file says and end the check before roslaunch reads the file. Sourced in
# every other step too, where it does nothing; nothing as root.
if [ "$(id -u)" != 0 ] && grep -qa load_config_default /proc/$$/cmdline 2>/dev/null; then
  echo /exam
  exit 0
fi
