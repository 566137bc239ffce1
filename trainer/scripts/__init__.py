"""The trainer's command lines, run as `python -m trainer.scripts.NAME`: the only modules with argparse and
`__main__`."""
