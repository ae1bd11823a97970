"""``python -m robomech.cli``."""

from robomech.cli import main

raise SystemExit(main())
