"""The underlay is rebuilt when the simulators' sources change, and only then: what their tests leave
beside them (a Hypothesis database, pytest's cache, byte code) is not a source."""
from exam_lab.grader.host.underlay import sources_digest


def package(tmp_path):
    root = tmp_path / 'drone_sim'
    (root / 'src' / 'drone_sim').mkdir(parents=True)
    (root / 'package.xml').write_text('<package/>')
    (root / 'src' / 'drone_sim' / 'noise.py').write_text('SIGMA = 1.0\n')
    return root


def test_a_source_changed_changes_the_digest(tmp_path):
    root = package(tmp_path)
    before = sources_digest([str(root)])
    (root / 'src' / 'drone_sim' / 'noise.py').write_text('SIGMA = 2.0\n')
    assert sources_digest([str(root)]) != before
    (root / 'src' / 'drone_sim' / 'led.py').write_text('')
    assert sources_digest([str(root)]) != before


def test_what_tests_leave_beside_the_sources_does_not(tmp_path):
    root = package(tmp_path)
    before = sources_digest([str(root)])
    (root / '.hypothesis' / 'examples' / '8ef6a2').mkdir(parents=True)
    (root / '.hypothesis' / 'examples' / '8ef6a2' / '1dd6f7').write_bytes(b'\x00\x01')
    (root / '.pytest_cache').mkdir()
    (root / '.pytest_cache' / 'README.md').write_text('cache')
    (root / 'src' / 'drone_sim' / '__pycache__').mkdir()
    (root / 'src' / 'drone_sim' / '__pycache__' / 'noise.cpython-311.pyc').write_bytes(b'\x00')
    (root / '.coverage').write_text('')
    assert sources_digest([str(root)]) == before


def test_a_file_gone_while_it_is_read_is_skipped(tmp_path, monkeypatch):
    """The listing and the read are not one step: a file deleted between them is not a failure."""
    import builtins
    root = package(tmp_path)
    gone = str(root / 'src' / 'drone_sim' / 'noise.py')
    real_open = builtins.open

    def vanishing(path, *args, **kwargs):
        if str(path) == gone:
            raise FileNotFoundError(2, 'No such file or directory', path)
        return real_open(path, *args, **kwargs)
    monkeypatch.setattr(builtins, 'open', vanishing)
    without = sources_digest([str(root)])
    monkeypatch.setattr(builtins, 'open', real_open)
    (root / 'src' / 'drone_sim' / 'noise.py').unlink()
    assert without == sources_digest([str(root)])
