"""Build of the C extension (everything else is declared in pyproject.toml)."""

from setuptools import Extension, setup

FLAGS = ["-O2", "-Wall", "-Wextra", "-Werror"]
setup(ext_modules=[Extension("scenegrep.readers._strem", ["src/scenegrep/readers/_strem.c"], extra_compile_args=FLAGS),
                   Extension("scenegrep.readers._mcap_index", ["src/scenegrep/readers/_mcap_index.c"],
                             extra_compile_args=FLAGS),
                   Extension("scenegrep.readers.ros._cdr_copy", ["src/scenegrep/readers/ros/_cdr_copy.c"],
                             extra_compile_args=FLAGS),
                   Extension("scenegrep.readers.ros._cdr_walk", ["src/scenegrep/readers/ros/_cdr_walk.c"],
                             extra_compile_args=FLAGS),
                   Extension("scenegrep.readers.ros._place", ["src/scenegrep/readers/ros/_place.c"],
                             extra_compile_args=[*FLAGS, "-ffp-contract=off"]),
                   Extension("scenegrep.scene._reach", ["src/scenegrep/scene/_reach.c"],
                             extra_compile_args=[*FLAGS, "-ffp-contract=off"]),
                   Extension("scenegrep.model._project", ["src/scenegrep/model/_project.c"],
                             extra_compile_args=[*FLAGS, "-ffp-contract=off"])])
