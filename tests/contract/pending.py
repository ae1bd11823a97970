"""TEMPORARY (issue 14): public names whose specs are still being written.  Must be empty and removed."""

PENDING: set[str] = {
    "robomech.__version__",
    "robomech.cli.main",
    "robomech.studies.Figure",
    "robomech.studies.Progress",
    "robomech.studies.Study",
    "robomech.studies.StudyResult",
    "robomech.studies.Table",
    "robomech.studies.available_studies",
    "robomech.studies.comparison_table",
    "robomech.studies.get_study",
    "robomech.studies.write_index",
    "robomech.studies.write_study_report",
}
