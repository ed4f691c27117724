"""A study's [search] run in waves: every value the search asks for is a run of the study
(the run id a grid with that value gives), run on the study's executor, one wave for the scan
of all points, then one per round of bisection."""

from trackbench.study.read.limits import quantity_of
from trackbench.study.spec import search as S
from trackbench.study.spec.study_file import search_run


def run_search(study, wave, say):
    """Search every grid point of the study: ``wave(runs)`` runs those of ``runs`` not completed
    (the scan of all points in one wave, then one wave per round of bisection); ``say(text)``
    hears how far the search is. Returns the search.PointSearch of every point."""
    def evaluate(asks):
        runs = [search_run(study, i, x) for i, x in asks]
        wave(runs)
        return [quantity_of(study, r) for r in runs]

    def on_round(searches, round_, rounds, asking):
        say(S.progress_line(searches, round_, rounds, asking))

    searches = S.search_limits(study.search, range(len(study.points)), evaluate, on_round)
    say(S.state_line(study.search, searches))
    return searches
