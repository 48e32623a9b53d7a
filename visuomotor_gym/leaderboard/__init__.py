"""The leaderboard: results on the standard protocol, kept honest by ``vmgym leaderboard check``.

* :mod:`.protocol`: ``leaderboard/protocol.json`` (episodes and first seed per env id, re-score sample);
* :mod:`.entries`: an entry on disk (results file, entry record with per-episode outcomes, policy file);
* :mod:`.policies`: policy-file formats (``eyecatch-params``; trained agents register theirs);
* :mod:`.submit`: ``vmgym leaderboard submit``;
* :mod:`.check`: every rule of ``vmgym leaderboard check``; :mod:`.history`: the git rule;
* :mod:`.pages`: the generated ``README.md`` and ``index.html`` (inline SVG plots);
* :mod:`.browser`: headless Chromium (screenshots and DOM dumps of the page, for tests and docs).
"""

from visuomotor_gym.leaderboard.check import CheckReport, check_leaderboard
from visuomotor_gym.leaderboard.entries import load_leaderboard
from visuomotor_gym.leaderboard.problems import Problem

__all__ = ["CheckReport", "Problem", "check_leaderboard", "load_leaderboard"]
