"""ROS 2 bags and MCAP files: raw messages -> decoded boxes and transforms -> frames.

Modules, one concept each: :mod:`.messages` (the records), :mod:`.msgdef` (message definitions),
:mod:`.cdr` (vectorised CDR decoding, the reference walk), :mod:`.cdr_layout` (a batch of one layout,
copied by C), :mod:`.cdr_walk` (any batch, walked by C), :mod:`.decoders` (per message type), :mod:`.transforms`
(the tf buffer), :mod:`.framing` (the incremental pipeline), :mod:`.chunks` and :mod:`.bag` (files to messages),
:mod:`.reader` (the ``ros-bag`` format).
"""
