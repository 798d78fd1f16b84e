"""BibTeX for the package and for the methods a run used: :func:`cite`.

As rebound's ``sim.cite()``: the package's own entry and Hamilton (1845) always,
then one entry per integrator, corrector, effect or tool the run used.  Each
entry's bibliographic data was checked against a readable source (the seeds'
title pages, rebound's ``citations.py``, the publishers' pages); a DOI is given
only where it was so checked, and an author list that could not be checked in
full ends in ``and others``.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

__all__ = ["ENTRIES", "cite", "keys_for"]

_PACKAGE = """@software{hamilton_orbits,
  author = {{The hamilton-orbits developers}},
  title = {hamilton-orbits: celestial mechanics and rigid-body rotation on one quaternion core},
  version = {%s},
  year = {2026},
  license = {BSD-3-Clause}
}"""

#: key -> BibTeX entry (without the package's own, which carries the version).
ENTRIES: dict[str, str] = {
    "hamilton1845": """@article{hamilton1845,
  author = {Hamilton, William Rowan},
  title = {On the application of the method of quaternions to some dynamical questions},
  journal = {Proceedings of the Royal Irish Academy},
  volume = {3},
  year = {1847},
  pages = {xxxvi--l},
  note = {Appendix; communicated July 14 and July 21, 1845}
}""",
    "everhart1985": """@inproceedings{everhart1985,
  author = {Everhart, Edgar},
  title = {An efficient integrator that uses {Gauss-Radau} spacings},
  booktitle = {Dynamics of Comets: Their Origin and Evolution},
  editor = {Carusi, A. and Valsecchi, G. B.},
  series = {Astrophysics and Space Science Library},
  volume = {115},
  publisher = {D. Reidel},
  year = {1985},
  pages = {185--202}
}""",
    "rein2015ias15": """@article{rein2015ias15,
  author = {Rein, Hanno and Spiegel, David S.},
  title = {{IAS15}: a fast, adaptive, high-order integrator for gravitational dynamics,
           accurate to machine precision over a billion orbits},
  journal = {Monthly Notices of the Royal Astronomical Society},
  volume = {446},
  number = {2},
  year = {2015},
  pages = {1424--1437},
  doi = {10.1093/mnras/stu2164}
}""",
    "pham2024": """@article{pham2024,
  author = {Pham, Dang and Rein, Hanno and Spiegel, David S.},
  title = {A new timestep criterion for {N}-body simulations},
  journal = {The Open Journal of Astrophysics},
  volume = {7},
  year = {2024},
  doi = {10.21105/astro.2401.02849}
}""",
    "duncan1998": """@article{duncan1998,
  author = {Duncan, Martin J. and Levison, Harold F. and Lee, Man Hoi},
  title = {A multiple time step symplectic algorithm for integrating close
           encounters},
  journal = {The Astronomical Journal},
  volume = {116},
  number = {4},
  year = {1998},
  pages = {2067--2077},
  doi = {10.1086/300541}
}""",
    "marsden1973": """@article{marsden1973,
  author = {Marsden, B. G. and Sekanina, Z. and Yeomans, D. K.},
  title = {Comets and nongravitational forces. {V}},
  journal = {The Astronomical Journal},
  volume = {78},
  year = {1973},
  pages = {211--225},
  doi = {10.1086/111402}
}""",
    "wisdom1991": """@article{wisdom1991,
  author = {Wisdom, Jack and Holman, Matthew},
  title = {Symplectic maps for the {N}-body problem},
  journal = {The Astronomical Journal},
  volume = {102},
  year = {1991},
  pages = {1528--1538},
  doi = {10.1086/115978}
}""",
    "rein2015whfast": """@article{rein2015whfast,
  author = {Rein, Hanno and Tamayo, Daniel},
  title = {{WHFAST}: a fast and unbiased implementation of a symplectic {Wisdom-Holman}
           integrator for long-term gravitational simulations},
  journal = {Monthly Notices of the Royal Astronomical Society},
  volume = {452},
  number = {1},
  year = {2015},
  pages = {376--388},
  doi = {10.1093/mnras/stv1257}
}""",
    "wisdom1996": """@article{wisdom1996,
  author = {Wisdom, Jack and Holman, Matthew and Touma, Jihad},
  title = {Symplectic correctors},
  journal = {Fields Institute Communications},
  volume = {10},
  year = {1996},
  pages = {217}
}""",
    "hairer1993": """@book{hairer1993,
  author = {Hairer, Ernst and N{\\o}rsett, Syvert P. and Wanner, Gerhard},
  title = {Solving Ordinary Differential Equations {I}: Nonstiff Problems},
  edition = {2nd revised},
  series = {Springer Series in Computational Mathematics},
  volume = {8},
  publisher = {Springer},
  address = {Berlin},
  year = {1993}
}""",
    "verlet1967": """@article{verlet1967,
  author = {Verlet, Loup},
  title = {Computer ``experiments'' on classical fluids. {I}. Thermodynamical properties
           of {Lennard-Jones} molecules},
  journal = {Physical Review},
  volume = {159},
  year = {1967},
  pages = {98--103},
  doi = {10.1103/PhysRev.159.98}
}""",
    "cincotta2000": """@article{cincotta2000,
  author = {Cincotta, Pablo M. and Sim{\\'o}, Carles},
  title = {Simple tools to study global dynamics in non-axisymmetric galactic
           potentials -- {I}},
  journal = {Astronomy and Astrophysics Supplement Series},
  volume = {147},
  year = {2000},
  pages = {205--228},
  doi = {10.1051/aas:2000108}
}""",
    "park2021": """@article{park2021,
  author = {Park, Ryan S. and Folkner, William M. and Williams, James G. and
            Boggs, Dale H.},
  title = {The {JPL} Planetary and Lunar Ephemerides {DE440} and {DE441}},
  journal = {The Astronomical Journal},
  volume = {161},
  number = {3},
  year = {2021},
  pages = {105},
  doi = {10.3847/1538-3881/abd414}
}""",
    "anderson1975": """@article{anderson1975,
  author = {Anderson, J. D. and others},
  title = {Experimental test of general relativity using time-delay data from
           {Mariner} 6 and {Mariner} 7},
  journal = {The Astrophysical Journal},
  volume = {200},
  year = {1975},
  pages = {221}
}""",
    "nobili1986": """@inproceedings{nobili1986,
  author = {Nobili, A. and Roxburgh, I. W.},
  title = {Simulation of general relativistic corrections in long term numerical
           integrations of planetary orbits},
  booktitle = {IAU Symposium 114},
  year = {1986},
  pages = {105}
}""",
    "tamayo2020": """@article{tamayo2020,
  author = {Tamayo, Daniel and Rein, Hanno and Shi, Pengshuai and Hernandez, David M.},
  title = {{REBOUNDx}: a library for adding conservative and dissipative forces to
           otherwise symplectic {N}-body integrations},
  journal = {Monthly Notices of the Royal Astronomical Society},
  volume = {491},
  number = {2},
  year = {2020},
  pages = {2885--2901},
  doi = {10.1093/mnras/stz2870}
}""",
}

#: the keys each method cites (the WH corrector's are added by keys_for)
_METHOD_KEYS = {
    "radau15": ("everhart1985", "rein2015ias15"),
    "wh": ("wisdom1991",),
    "leapfrog": ("verlet1967",),
    "dop853": ("hairer1993",),
}
#: the effects whose model is DE440's (Park et al. 2021)
_DE440_EFFECTS = frozenset({"eih", "lense_thirring", "zonal", "moon_figure", "earth_tides",
                            "kuiper_ring"})
_EFFECT_KEYS = {"gr": ("anderson1975", "tamayo2020"), "gr_potential": ("nobili1986",),
                "nongrav": ("marsden1973",)}


def _effect_names(effects: Any) -> tuple[str, ...]:
    names = getattr(effects, "names", effects)  # an EffectSet, or a list of names/dicts
    return tuple(e["name"] if isinstance(e, dict) else str(e) for e in names or ())


def _describe(run: Any, effects: Iterable[Any], variational: bool,
              ) -> tuple[str | None, dict[str, Any], tuple[str, ...], bool]:
    """(method name, its options, effect names, variational) of ``run``."""
    if run is None or isinstance(run, str):
        return run, {}, _effect_names(effects), variational
    method = run.method
    if isinstance(method, str):  # a Trajectory: the name only
        return (method, {}, _effect_names(run.effects),
                variational or getattr(run, "megno", None) is not None)
    # a Simulation: its typed method; variational if its right-hand side has tangents
    var = run.rhs.tangent is not None
    return method.name, method.options(), _effect_names(run.effects), variational or var


def keys_for(run: Any = None, effects: Iterable[Any] = (), *, variational: bool = False,
             ephemeris: bool = False, corrector: int = 0
             ) -> list[str]:
    """The keys of :data:`ENTRIES` that :func:`cite` gives for the same arguments.

    Examples
    --------
    >>> keys_for("wh", ["gr_potential"], corrector=11)
    ['hamilton1845', 'wisdom1991', 'duncan1998', 'wisdom1996', 'rein2015whfast', 'nobili1986']
    """
    name, options, names, variational = _describe(run, effects, variational)
    corrector = options.get("corrector", corrector)
    keys = ["hamilton1845"]
    if name is not None:
        if name not in _METHOD_KEYS:
            raise ValueError(f"Expected a method among {', '.join(_METHOD_KEYS)}, got {name!r}")
        keys += _METHOD_KEYS[name]
    if name == "radau15" and options.get("criterion", "prs23") == "prs23" \
            and getattr(run, "dt", None) is None:  # (a fixed step has no rule)
        keys.append("pham2024")  # the default step rule (a name, a Trajectory: its default)
    if name == "wh" and options.get("coordinates", "democratic_heliocentric") != "jacobi":
        keys.append("duncan1998")  # the default splitting, democratic heliocentric
    if name == "wh" and corrector:  # the correctors, at WHFast's orders
        keys += ("wisdom1996", "rein2015whfast")
    for effect in names:
        keys += _EFFECT_KEYS.get(effect, ())
    if ephemeris or _DE440_EFFECTS.intersection(names):
        keys.append("park2021")
    if variational:
        keys.append("cincotta2000")
    return list(dict.fromkeys(keys))


def cite(run: Any = None, effects: Iterable[Any] = (), *, variational: bool = False,
         ephemeris: bool = False, corrector: int = 0) -> str:
    """BibTeX for hamilton-orbits and for the methods a run used (as rebound's
    ``sim.cite()``).

    Parameters
    ----------
    run : Trajectory, Simulation, str or None
        What to cite: a :class:`~hamilton_orbits.Trajectory` or a
        :class:`~hamilton_orbits.Simulation` (its method, options, effects and
        whether it integrated variational equations), or a method name
        (``"radau15"``, ``"wh"``, ``"leapfrog"``, ``"dop853"``); None: the package
        and Hamilton (1845) only.
    effects : sequence of str or dict
        With a method name: the effects, as ``Simulation`` takes them.
    variational : bool
        With a method name: the run computed MEGNO (Cincotta & Simo 2000).  A
        Trajectory or Simulation says so itself.
    ephemeris : bool
        The initial state came from JPL DE440 (``System.from_ephemeris``): cite
        Park et al. (2021), as the solar-system effects do.
    corrector : int
        With ``"wh"`` as a name: the corrector's order (0: none).  (A
        Trajectory keeps the method's name only: cite the Simulation, or pass
        these, to cite the corrector.)  A method given by name, or a Trajectory's,
        cites its default options' papers: radau15's step rule (Pham, Rein &
        Spiegel 2024), wh's democratic-heliocentric splitting (Duncan, Levison &
        Lee 1998).

    Returns
    -------
    str
        The entries, separated by blank lines: the package's first, then
        Hamilton (1845), then one per method, effect and tool used.

    Examples
    --------
    >>> from hamilton_orbits import cite
    >>> bib = cite("radau15")
    >>> [line.split("{")[1].rstrip(",") for line in bib.splitlines() if line.startswith("@")]
    ['hamilton_orbits', 'hamilton1845', 'everhart1985', 'rein2015ias15', 'pham2024']
    """
    from hamilton_orbits import __version__

    keys = keys_for(run, effects, variational=variational, ephemeris=ephemeris,
                    corrector=corrector)
    return "\n\n".join([_PACKAGE % __version__, *(ENTRIES[k] for k in keys)]) + "\n"
