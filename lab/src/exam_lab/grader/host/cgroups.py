"""The cgroups of a box and of its judge: made below root's own, bounded, joined, read, removed.

cgroup v1 (``memory`` + ``pids`` + ``cpu``) or v2, where the machine lets us make one; [] where it does
not (the box is then bounded per process only: :func:`~exam_lab.grader.host.limits.prlimit`).
cgroup v2 is untested (it needs the controllers enabled in the parent's cgroup.subtree_control).
"""
import os

from exam_lab.grader.host.limits import JUDGE_SHARES, MASTER_MEMORY_BYTES, PROBE_MEMORY_BYTES

#: Period of the CPU quota (v1 cpu.cfs_period_us, v2 cpu.max), microseconds.
CPU_PERIOD_US = 100000


def _own_cgroups():
    """``{controller: (hierarchy root, this process's path)}``; v2 as controller ``''``."""
    found = {}
    try:
        with open('/proc/self/cgroup') as f:
            for line in f:
                _, controllers, path = line.rstrip('\n').split(':', 2)
                for name in controllers.split(','):
                    if name in ('memory', 'pids', 'cpu', 'cpuacct') and os.path.isdir('/sys/fs/cgroup/%s' % name):
                        found[name] = ('/sys/fs/cgroup/%s' % name, path)
                    elif controllers == '' and os.path.isfile('/sys/fs/cgroup/cgroup.controllers'):
                        found[''] = ('/sys/fs/cgroup', path)
    except OSError:
        pass
    return found


def cgroup_limits(memory, shares, pids=None, cpus=None, v2=False):
    """``[(controller, file, value)]`` that bound a cgroup: ``memory`` bytes, CPU weight ``shares``
    (v1 units), at most ``pids`` processes and ``cpus`` cores (None: no bound). The controller is ''
    under cgroup v2 (one folder for all)."""
    quota = int(cpus * CPU_PERIOD_US) if cpus else None
    if v2:
        limits = [('', 'memory.max', memory), ('', 'cpu.weight', max(1, min(10000, shares * 100 // 1024)))]
        if quota:
            limits.append(('', 'cpu.max', '%d %d' % (quota, CPU_PERIOD_US)))
        if pids:
            limits.append(('', 'pids.max', pids))
        return limits
    limits = [('memory', 'memory.limit_in_bytes', memory), ('cpu', 'cpu.shares', shares)]
    if quota:
        limits += [('cpu', 'cpu.cfs_period_us', CPU_PERIOD_US), ('cpu', 'cpu.cfs_quota_us', quota)]
    if pids:
        limits.append(('pids', 'pids.max', pids))
    return limits


def make_cgroups(name, memory, shares, pids=None, cpus=None):
    """Folders of new cgroups called ``name`` with the limits of :func:`cgroup_limits`; [] when the
    machine does not let us. cgroup v1 needs the ``memory`` controller (and ``pids`` when ``pids`` is
    bounded); without ``cpu`` the CPU is not bounded."""
    own = _own_cgroups()
    made = {}
    try:
        if 'memory' in own and ('pids' in own or not pids):
            limits = [l for l in cgroup_limits(memory, shares, pids, cpus) if l[0] in own]
        elif '' in own:
            limits = cgroup_limits(memory, shares, pids, cpus, v2=True)
        else:
            return []
        for controller, limit_file, value in limits:
            if controller not in made:
                root, path = own[controller]
                made[controller] = os.path.join(root, path.lstrip('/'), name)
                _fresh_folder(made[controller])
            with open(os.path.join(made[controller], limit_file), 'w') as f:
                f.write(str(value))
        if 'cpuacct' in own and '' not in made:
            _counting_folder(own['cpuacct'], name, made)
        return list(made.values())
    except OSError:
        remove_cgroups(list(made.values()))
        return []


def _counting_folder(own, name, made):
    """cgroup v1's ``cpuacct`` folder ``name`` (counted, never bounded: :func:`cpu_use`) into ``made``,
    unless it is a folder made already (``cpu,cpuacct`` mounted together); one that cannot be made
    costs the count only, never the bounds."""
    folder = os.path.join(own[0], own[1].lstrip('/'), name)
    if any(os.path.realpath(folder) == os.path.realpath(other) for other in made.values()):
        return
    try:
        _fresh_folder(folder)
        made['cpuacct'] = folder
    except OSError:
        pass


def cpu_use(folders):
    """CPU s every process of the cgroups among ``folders`` used so far (v1 ``cpuacct.usage``, v2
    ``cpu.stat``'s ``usage_usec``), or None when none of them counts it. The box's stages are timed by
    it: what runs under bubblewrap is never waited for by the grader, so ``getrusage`` misses it."""
    for folder in folders:
        try:
            with open(os.path.join(folder, 'cpuacct.usage')) as f:
                return int(f.read()) / 1e9
        except (OSError, ValueError):
            pass
        try:
            with open(os.path.join(folder, 'cpu.stat')) as f:
                stat = dict(line.split() for line in f if len(line.split()) == 2)
            if 'usage_usec' in stat:
                return int(stat['usage_usec']) / 1e6
        except (OSError, ValueError):
            pass
    return None


def judge_cgroups(slot):
    """``{"master": [folders], "probe": [folders]}``: the judge's cgroups of box slot ``slot``, bounded
    in memory and outweighing the box for CPU."""
    return {'master': make_cgroups('exam-master-%d' % slot, MASTER_MEMORY_BYTES, JUDGE_SHARES),
            'probe': make_cgroups('exam-judge-%d' % slot, PROBE_MEMORY_BYTES, JUDGE_SHARES)}


def _fresh_folder(folder):
    """mkdir, after removing an empty one a crashed grader left (its slot's lock was released)."""
    try:
        os.mkdir(folder)
    except FileExistsError:
        os.rmdir(folder)
        os.mkdir(folder)


def remove_cgroups(folders):
    for folder in reversed(folders):
        try:
            os.rmdir(folder)
        except OSError:
            pass


def join(folders):
    """The command-line prefix that puts the command in the cgroups ``folders`` (then execs it)."""
    if not folders:
        return []
    return ['sh', '-c', 'for g in "$@"; do case "$g" in --) shift; break;; esac; '
            'echo $$ > "$g/cgroup.procs" || exit 125; shift; done; exec "$@"', 'sh'] + list(folders) + ['--']


def memory_use(folders):
    """What the memory cgroup among ``folders`` saw: ``{"limit", "peak" (bytes, None where the kernel
    does not say), "oom_kills"}``; None without one. v1: memory.max_usage_in_bytes and oom_control;
    v2: memory.peak and memory.events."""
    for folder in folders:
        v1 = os.path.join(folder, 'memory.limit_in_bytes')
        v2 = os.path.join(folder, 'memory.max')
        if not os.path.isfile(v1) and not os.path.isfile(v2):
            continue
        names = ('memory.limit_in_bytes', 'memory.max_usage_in_bytes', 'memory.oom_control') \
            if os.path.isfile(v1) else ('memory.max', 'memory.peak', 'memory.events')
        values = []
        for name in names:
            try:
                with open(os.path.join(folder, name)) as f:
                    values.append(f.read())
            except OSError:
                values.append('')
        events = dict(line.split() for line in values[2].splitlines() if len(line.split()) == 2)
        limit, peak = values[0].strip(), values[1].strip()
        return {'limit': int(limit) if limit.isdigit() else None, 'peak': int(peak) if peak.isdigit() else None,
                'oom_kills': int(events.get('oom_kill', '0'))}
    return None


def reset_memory_peak(folders):
    """Start the peak of the memory cgroups among ``folders`` anew (v1; v2 kernels before 6.12 cannot)."""
    for folder in folders:
        for name in ('memory.max_usage_in_bytes', 'memory.peak'):
            try:
                with open(os.path.join(folder, name), 'w') as f:
                    f.write('0')
            except OSError:
                pass
