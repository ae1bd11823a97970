"""Bad-input specs of robomech.cli (the names added by the usability work; main is pending)."""

from contract_spec import BAD_STR, Exempt, Spec

from robomech.cli import Command

P = "robomech.cli."


def _noop(*args, **kwargs):
    return 0


SPECS = {
    P + "Command": Spec(
        call=Command,
        args={"name": "sweep", "help": "a sweep", "add_arguments": _noop, "run": _noop, "description": ""},
        options={
            "name": (*BAD_STR, "", "two words", " sweep"),
            "help": (None, 1),
            "add_arguments": (None, "f", 1),
            "run": (None, "f"),
            "description": (None, 1),
        },
    ),
    P + "available_commands": Exempt("registry: takes no input, returns the discovered subcommands"),
    P + "build_parser": Exempt("takes no input: builds the argparse parser from the registry"),
}
