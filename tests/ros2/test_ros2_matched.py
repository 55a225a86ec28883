"""fsmscope.ros2.subscription: cyclonedds 11.0.1 raises IndexError from get_matched_publications when
a writer matches between its count and its listing (seen in CI: the reader's thread died and no
message arrived after). The listing is asked again and counts that writer too."""

from fsmscope.ros2.subscription import _matched_publications


class ReaderMatchedWhileListing:
    """What cyclonedds' DataReader does when a writer matches during the call: the first listing
    indexes past the array it made, the next one lists every writer."""

    def __init__(self) -> None:
        self.calls = 0

    def get_matched_publications(self) -> list[int]:
        self.calls += 1
        if self.calls == 1:
            raise IndexError("invalid index")
        return [11, 12]


def test_a_writer_matched_while_the_reader_lists_them_is_listed_not_a_crash():
    assert _matched_publications(ReaderMatchedWhileListing()) == {11, 12}
