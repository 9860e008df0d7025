# SPDX-License-Identifier: GPL-3.0-or-later
"""Loads a script of experiments/ as a module, for the tests of its functions."""
import importlib.util
import os

SOURCE = os.environ.get("FIBERFLUID_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))


def load(name):
    """experiments/<name>.py as a module."""
    path = os.path.join(SOURCE, "experiments", name + ".py")
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
