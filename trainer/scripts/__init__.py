"""The trainer's command lines: the only modules with argparse and `__main__`, run as `python -m trainer.scripts.NAME`."""
