"""Build of the C extension (everything else is declared in pyproject.toml)."""

from setuptools import Extension, setup

setup(ext_modules=[Extension("scenegrep.readers._strem", ["src/scenegrep/readers/_strem.c"],
                             extra_compile_args=["-O2", "-Wall", "-Wextra", "-Werror"])])
