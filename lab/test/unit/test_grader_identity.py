"""Who a submission is (score/identity.py, the class listing, the Slurm host): the participant number
is read from the entry's name as Moodle wrote it (``_<number>_assignsubmission_``), a name shortened to
fit a folder keeps that part whole, and what is kept across runs and checked on the way back is that
number and Moodle's folder. No ROS, no box."""
import os
import zipfile

from exam_lab.grader.boxed import archives, classlist
from exam_lab.grader.score import identity


def flat_download(path, entries):
    """A flat "download all submissions" zip (folders off): each ``name`` an upload at the top, deflated
    as Moodle's zip_packer writes it."""
    with zipfile.ZipFile(str(path), 'w', zipfile.ZIP_DEFLATED) as zf:
        for name, data in entries:
            zf.writestr(name, data)
    return str(path)


def exam_zip():
    import io
    made = io.BytesIO()
    with zipfile.ZipFile(made, 'w') as zf:
        zf.writestr('exam/package.xml', '<package format="2"><name>exam</name></package>')
    return made.getvalue()


def test_a_shortened_flat_entry_keeps_moodles_number_never_one_of_the_students_file_name(tmp_path):
    """Ann (participant 11, a long name as Moodle allows: 100 characters each for the first and the
    last) names her upload so that its end reads like Bob's (participant 12): the entry is longer than
    a folder name may be, so it is shortened; the number read from the shortened name is still Ann's
    (it used to keep the end the student chose, cut the name's end with Moodle's part, and give her
    Bob's number)."""
    trap = 'x' * 20 + '_12_assignsubmission_file_exam.zip'
    ann = 'Ann %s' % ('L' * 200)
    entries = [('%s_11_assignsubmission_file_%s' % (ann, trap), exam_zip()),
               ('Bob Ray_12_assignsubmission_file_exam.zip', exam_zip())]
    students = classlist.list_students(flat_download(tmp_path / 'class.zip', entries), str(tmp_path / 'scratch'), {})
    assert [name for name, _ in students][1] == 'Bob Ray'
    shortened = os.path.basename(students[0][1])
    assert len(shortened.encode()) <= archives.NAME_MAX and shortened.endswith('.zip')
    assert shortened.startswith('Ann LLL') and '_11_assignsubmission_file_' in shortened
    assert [identity.participant_number(os.path.basename(path)) for _, path in students] == [11, 12]


def test_a_long_name_in_another_script_keeps_its_number_and_loses_its_middle():
    name = 'Жанна %s_4711_assignsubmission_file_' % ('Ш' * 140)
    fitted = classlist._fitting(name)
    assert len(fitted.encode()) <= archives.NAME_MAX and fitted.startswith('Жанна Ш') and '-' in fitted
    assert fitted.endswith('Ш_4711_assignsubmission_file_') and identity.participant_number(fitted) == 4711
    flat = 'Ян %s_42_assignsubmission_file_%s.tar.gz' % ('Ю' * 60, 'я' * 150)
    fitted = classlist._fitting(flat)
    assert len(fitted.encode()) <= archives.NAME_MAX and fitted.endswith('я.tar.gz')
    assert '_42_assignsubmission_file_' in fitted and identity.participant_number(fitted) == 42
    assert classlist._fitting('short_1_assignsubmission_file_') == 'short_1_assignsubmission_file_'


def test_moodles_part_is_found_where_moodle_wrote_it():
    assert identity.moodle_span('Jane Doe_1234_assignsubmission_file_') == (8, 36)
    assert identity.moodle_span('Jane Doe_1234_assignsubmission_onlinetext_onlinetext.html') == (8, 42)
    assert identity.moodle_span('Jane Doe') is None


def test_root_lists_a_class_folder_by_names_and_kinds_as_the_box_lists_an_unpacked_one(tmp_path):
    """host.classfolder (root) and boxed.classlist (the intake's box) give one listing: the pure
    score.identity.class_listing over the entries' names and kinds (lstat), nothing opened."""
    from exam_lab.grader.host import classfolder
    klass = tmp_path / 'class'
    (klass / 'Ann_1_assignsubmission_file_').mkdir(parents=True)
    (klass / 'Bob_2_assignsubmission_file_exam.zip').write_bytes(exam_zip())
    (klass / 'Cy_3_assignsubmission_file_report.pdf').write_bytes(b'%PDF-1.4')
    os.symlink(str(tmp_path), str(klass / 'Dee_4_assignsubmission_file_'))
    os.mkfifo(str(klass / 'Eve_5_assignsubmission_file_notes.txt'))
    (klass / '__MACOSX').mkdir()
    root_refused, box_refused = {}, {}
    listed = classfolder.list_students(str(klass), root_refused)
    assert listed == classlist.list_students(str(klass), None, box_refused) and root_refused == box_refused
    assert [name for name, _ in listed] == ['Ann', 'Bob', 'Dee', 'Cy']
    assert root_refused == {str(klass / 'Dee_4_assignsubmission_file_'): identity.LINKED}
