"""``python -m robomech``: the ``robomech`` command."""

from robomech.cli import main

raise SystemExit(main())
