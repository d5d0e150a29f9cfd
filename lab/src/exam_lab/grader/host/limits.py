"""The bounds of a box and of the judge beside it: memory, processes, CPU, files. No rospy here.

A box's whole memory, its CPU quota and weight, and the judge's memory and weight are a cgroup's
(:mod:`~exam_lab.grader.host.cgroups`, where the machine lets root make one); the bounds of each
process (address space, processes of the uid, CPU time, file size, open files, no core) are
``prlimit``'s, always (:func:`prlimit`).
"""
import os

#: The whole box (cgroup).
MEMORY_BYTES = 2 << 30
#: Each process of a box (prlimit: rospy reserves 64 MB malloc arenas per thread).
ADDRESS_SPACE_BYTES = 4 << 30
PROCESSES = 512                  # threads count: a rospy node has ~15, roslaunch ~10
CPU_SECONDS = 300                # each process
FILE_BYTES = 64 << 20            # each file written, logs included
OPEN_FILES = 1024
#: CPU weights (cgroup v1 cpu.shares; v2 cpu.weight = shares * 100 / 1024): a box has the default, the
#: judge's master and probe four times it, so they keep their timing beside a box that burns its quota.
BOX_SHARES = 1024
JUDGE_SHARES = 4096
#: The least CPU quota of a box, in cores (a build or a node needs one at times).
MIN_BOX_CPUS = 0.5
#: The master the student's nodes talk to (roscore: rosmaster and rosout), and the probe: their memory.
MASTER_MEMORY_BYTES = 384 << 20
PROBE_MEMORY_BYTES = 512 << 20
WORK_BYTES = 512 << 20           # the box's work folder: build/ + devel/
TMP_BYTES = 64 << 20             # each of /tmp, /var/tmp, /dev/shm, HOME


def box_cpus(jobs, cores=None):
    """The CPU quota of one box, in cores, when ``jobs`` gradings run side by side on ``cores`` (default
    this machine's): an equal part of the machine, at least MIN_BOX_CPUS."""
    cores = cores or os.cpu_count() or 1
    return max(MIN_BOX_CPUS, float(cores) / max(1, jobs))


def prlimit():
    """The command-line prefix that bounds each process of a box (then runs the rest of the line)."""
    return ['prlimit', '--as=%d' % ADDRESS_SPACE_BYTES, '--nproc=%d' % PROCESSES, '--cpu=%d' % CPU_SECONDS,
            '--fsize=%d' % FILE_BYTES, '--nofile=%d' % OPEN_FILES, '--core=0', '--']
