"""While drilling (docs/live.md): following a growing file, a folder of arriving parts
(:mod:`~drillfric.live.source`) or a WITS level 0 stream (:mod:`~drillfric.live.wits0_receiver`)
and estimating its segments as they close (:mod:`~drillfric.live.run`), with a live page
(:mod:`~drillfric.live.page`); replaying a file as a logger or a WITS0 recorder would
(:mod:`~drillfric.live.replay`, :mod:`~drillfric.live.wits0_server`)."""
