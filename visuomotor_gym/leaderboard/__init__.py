"""The leaderboard: results on the standard protocol, kept honest by ``vmgym leaderboard check``.

* :mod:`.protocol`: ``leaderboard/protocol.json`` (episodes and first seed per env id, re-score sample);
* :mod:`.entries`: an entry on disk (results file, entry record with per-episode outcomes, policy file);
* :mod:`.policies`: policy-file formats (``eyecatch-params``, ``belief-mpc-params``, the pickle-free
  ``ppo-npz``; the pickled ``sb3-ppo-zip`` is retired and never loaded);
* :mod:`.submit`: ``vmgym leaderboard submit``;
* :mod:`.check`: every rule of ``vmgym leaderboard check``; :mod:`.rescore`: re-playing entries from their
  policy files as the evaluator played them; :mod:`.history`: the git rules (immutable entries, new vs
  existing entries, protocol.json and superseded.json history, provenance commits);
* :mod:`.pages`: the generated ``README.md`` and ``index.html`` (inline SVG plots);
* :mod:`.browser`: headless Chromium (screenshots and DOM dumps of the page, for tests and docs).
"""

from visuomotor_gym.leaderboard.check import CheckReport, check_leaderboard
from visuomotor_gym.leaderboard.entries import load_leaderboard
from visuomotor_gym.leaderboard.problems import Problem

__all__ = ["CheckReport", "Problem", "check_leaderboard", "load_leaderboard"]
