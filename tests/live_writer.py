"""A live MCAP writer for the ``--follow`` tests, run as its own process:

    python tests/live_writer.py OUT.mcap PLAN.json

PLAN: ``{"pause": S, "messages": [...]}``, each message a
:class:`~scenegrep.readers.mcap_follow.RawMessage` as a dict, its bytes in base64. The writer
creates OUT with the MCAP header, prints ``ready`` and waits for a line on its standard input;
then it appends the messages one by one, unchunked, each record in two writes 3 ms apart (a
reader polling the file sees half-written records), prints ``K T`` after the K-th message's last
byte is written (T: ``time.monotonic()``, the system-wide monotonic clock that the test reads
too) and sleeps ``pause`` seconds; at the end it writes the summary and footer and prints
``done``.
"""

from __future__ import annotations

import base64
import io
import json
import os
import sys
import time
from pathlib import Path

from mcap.writer import CompressionType, Writer


def has_open(pid: int, path: Path, seconds: float) -> bool:
    """Whether process ``pid`` opens ``path`` (has loaded its query and reads the file) within
    ``seconds``; polled every 10 ms."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            if any(Path(f"/proc/{pid}/fd/{fd}").resolve() == path.resolve() for fd in os.listdir(f"/proc/{pid}/fd")):
                return True
        except OSError:
            pass
        time.sleep(0.01)
    return False


def main(out: str, plan_path: str) -> None:
    plan = json.loads(Path(plan_path).read_text())
    buffer = io.BytesIO()
    writer = Writer(buffer, compression=CompressionType.NONE, use_chunking=False)
    writer.start("ros2", "scenegrep tests")
    fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)

    def flush(split: bool) -> None:
        data = buffer.getvalue()
        buffer.seek(0)
        buffer.truncate()
        if split and len(data) > 1:
            os.write(fd, data[: len(data) // 2])
            time.sleep(0.003)
            data = data[len(data) // 2 :]
        os.write(fd, data)

    flush(split=False)
    print("ready", flush=True)
    sys.stdin.readline()
    channels: dict[str, int] = {}
    for number, message in enumerate(plan["messages"]):
        topic = message["topic"]
        if topic not in channels:
            data = base64.b64decode(message["schema_data"])
            schema = writer.register_schema(message["schema_name"], message["schema_encoding"], data)
            channels[topic] = writer.register_channel(topic, message["message_encoding"], schema)
        log_time = message["log_time"]
        writer.add_message(
            channels[topic], log_time=log_time, data=base64.b64decode(message["data"]), publish_time=log_time
        )
        flush(split=True)
        print(number, time.monotonic(), flush=True)
        time.sleep(plan["pause"])
    writer.finish()
    flush(split=False)
    os.close(fd)
    print("done", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
