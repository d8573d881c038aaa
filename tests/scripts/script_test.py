"""The command line every test of tests/scripts shares: --script names the script under test."""
import argparse
import sys
import unittest


def main(module):
    """Sets module.SCRIPT from --script and runs the module's tests with the remaining arguments."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--script", required=True)
    args, rest = parser.parse_known_args()
    module.SCRIPT = args.script
    unittest.main(module=module, argv=[sys.argv[0], *rest])
