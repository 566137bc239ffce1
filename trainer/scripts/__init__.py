"""The trainer's command lines, run as `python -m trainer.scripts.NAME`: the only modules that parse a command
line (each from its settings dataclass: cli.parse_settings) and have `__main__`."""
