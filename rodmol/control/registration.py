"""rodmol's gymnasium environments, registered when rodmol is imported.

Each is registered by name with an entry point ``"module:Class"``, so
``gymnasium.make("rodmol/Reach-v0")`` works after ``import rodmol`` alone and
imports the environment's module (:mod:`rodmol.control.envs`) only then.
Without gymnasium nothing is registered and rodmol imports as before;
gymnasium's own import costs about 20-40 ms after rodmol's (numpy is shared).
"""

#: Each environment's id -> its entry point (gymnasium's ``"module:Class"``).
ENVIRONMENTS = {"rodmol/Reach-v0": "rodmol.control.envs:ReachEnv",
                "rodmol/OctopusCrawl-v0": "rodmol.control.crawl:OctopusCrawlEnv"}


def register_environments():
    """Register :data:`ENVIRONMENTS` with gymnasium (those not registered yet); returns
    False, doing nothing, without gymnasium."""
    try:
        from gymnasium.envs.registration import register, registry
    except ImportError:  # gymnasium is optional (pip install rodmol[rl])
        return False
    for env_id, entry_point in ENVIRONMENTS.items():
        if env_id not in registry:
            register(env_id, entry_point=entry_point)
    return True
