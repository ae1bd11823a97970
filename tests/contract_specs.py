"""Bad-input specs of the top-level robomech package and its command line."""

from contract_spec import CONSTANT, Exempt

SPECS = {
    "robomech.__version__": CONSTANT,
    "robomech.cli.main": Exempt(
        "CLI entry point (a function): bad arguments are argparse usage errors (exit status 2), "
        "tested in tests/studies/test_cli_and_reports.py"
    ),
}
