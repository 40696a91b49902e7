"""The command line's exit codes: 0 success (for queries: some match), 1 no match, 2 user error,
3 some source or trace failed while the others were done, 130 interrupted."""

EXIT_NO_MATCH = 1
EXIT_USER_ERROR = 2
EXIT_SOME_FAILED = 3
EXIT_INTERRUPTED = 130
