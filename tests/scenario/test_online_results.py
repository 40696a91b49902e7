"""scenario.online.online_results: how live chunks reach the matcher, labelled or not (the routing;
the labels and matches themselves are tested in tests/label/test_online.py and the CLI tests)."""

from __future__ import annotations

from dataclasses import dataclass, field

from scenegrep.scenario.online import final_results, online_results


@dataclass
class Chunk:
    name: str
    behaviours: object = None


@dataclass
class Labeller:
    """Holds unlabelled chunks two at a time; knows its delay after the first push."""

    held: list = field(default_factory=list)
    pushes: int = 0

    def delay(self):
        return "2 chunks later" if self.pushes else None

    def push(self, chunk):
        self.pushes += 1
        self.held.append(chunk.name)
        if len(self.held) < 2:
            return None
        out, self.held = Chunk("+".join(self.held), "labelled"), []
        return out

    def finish(self):
        out, self.held = (Chunk("+".join(self.held), "labelled") if self.held else None), []
        return out


class Matcher:
    """Reports every pushed trace as a result."""

    def push(self, trace):
        return [trace.name]


def test_one_list_per_chunk_labelled_chunks_flush_the_labeller_first():
    chunks = [Chunk("a"), Chunk("b"), Chunk("c"), Chunk("L", "labels"), Chunk("d")]
    labeller, delays = Labeller(), []
    per_chunk = list(online_results(chunks, Matcher(), labeller, delays.append))
    assert per_chunk == [[], ["a+b"], [], ["c", "L"], []]
    assert final_results(Matcher(), labeller) == ["d"]
    assert final_results(Matcher(), labeller) == []
    assert delays == ["2 chunks later"]  # once, when first known


def test_a_stopped_input_still_gets_the_held_frames():
    labeller = Labeller()
    results = online_results(iter([Chunk("a"), Chunk("b"), Chunk("c")]), Matcher(), labeller)
    assert [next(results), next(results), next(results)] == [[], ["a+b"], []]
    results.close()  # Ctrl-C: the generator is abandoned with "c" held
    assert final_results(Matcher(), labeller) == ["c"]
