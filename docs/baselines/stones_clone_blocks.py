"""Diagnostic for docs/baselines/rl.md "The same idea on SteppingStones-v0": which block of the cloned action fails? The teacher and the student see the same observation
stream; the played action takes the footstep block (0-3) from one and the look block (4-8) from the other.

    python docs/baselines/stones_clone_blocks.py baselines/ppo/policies/ppo-free-clone__SteppingStones-v0.npz
"""
import sys
import gymnasium as gym, numpy as np, visuomotor_gym  # noqa: F401
from visuomotor_gym.agents import make_agent
P = sys.argv[1]
env = gym.make("SteppingStones-v0")
for feet, look in (("teacher", "student"), ("student", "teacher")):
    ok = 0
    for s in range(40):
        t = make_agent("lookahead", "SteppingStones-v0", 9); st = make_agent(f"ppo:{P}", "SteppingStones-v0", 9)
        x, _ = env.reset(seed=s); done = False; first = True
        while not done:
            at = t.predict(x)[0]; a_s = st.predict(x, episode_start=np.array([first]))[0]; first = False
            src = {"teacher": at, "student": a_s}
            a = np.concatenate([src[feet][:4], src[look][4:]]).astype(np.float32)
            x, r, te, tr, info = env.step(a); done = te or tr
        ok += bool(info["is_success"])
    print(f"feet={feet} look={look}: {ok}/40 crossed (seeds 0-39)")
