"""Queries over streams, as they are read: what ``spre``'s stream modes and the online commands run.

A stream is searched frame by frame as it arrives, in memory that does not grow with it, and each
match is handed out as soon as the frame that completes it has been read. The package's modules,
lowest first:

- :mod:`.latency`: each frame's and each match's latency, and their median and 99th percentile;
- :mod:`.live`: live inputs: an MCAP file followed as it is written, MCAP or JSON documents on
  standard input, decoded into chunks of frames with their latency meter;
- :mod:`.spre`: SpRE over streams as STREM searches them (each input's traces one by one, or a live
  input), how each match is written, and the names a live stream lacks;
- :mod:`.scenario`: a scenario query over a live input (labelled online where it has no labels),
  its results as results-table rows, and the program objects no frame of the stream can be.

Over whole files, the dataset engine (:mod:`scenegrep.dataset`) runs the same queries.
"""
