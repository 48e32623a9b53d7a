"""The embodiment core every task family composes: the environment skeleton (:mod:`.env`), the eye
(:mod:`.eye`), the retina and its visual targets (:mod:`.retina`), the head (:mod:`.head`), body
frames (:mod:`.frames`), observation blocks (:mod:`.observation`) and argument checks (:mod:`.args`).

The core imports nothing from ``tasks/`` or ``envs/``: bodies (``body/``) and tasks (``tasks/``)
build on it, and the public env classes (``envs/``) compose them.
"""
