"""A site's parameters for the kinematic check (SPEC §3 site file, TOML), checked key by key.

The user gives every value (no hazard database, no modal analysis): the hazard a_g (in g), F₀,
T_C* (s) at the SLV's return period, the soil and topographic categories, FC, q, the mechanism's
height Z (m) and, for Z > 0, the building's height H (m) and storeys n.  Keys added for the
Circolare 2019 (all optional; the 2009 check refuses them, it has no use for them):

- ``T1`` (s), ``xi1`` (percent): the main structure's first-mode period and equivalent viscous
  damping, which the 2019 floor acceleration at Z > 0 needs (§C7.2.3, §C8.7.1.2.1.4); ``xi1`` is
  required there (the text gives a range, 10–20 % for masonry at the ultimate limit state, not
  a value); without ``T1`` the estimate C₁ H^¾ of NTC 2018 Eq. 7.3.6 is taken, as §C7.2.3 allows;
- ``ag_SLC`` (g), ``F0_SLC``, ``Tc_star_SLC`` (s): the hazard at the SLC's return period, all
  three or none; with them the 2019 check adds the SLC displacement check.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from alma.seismic.spectrum import elastic_spectrum

#: The editions of the Circolare whose checks are implemented; the first is the default.
EDITIONS = ("2019", "2009")
#: The hazard at the SLC's return period: all three keys or none.
SLC_KEYS = ("ag_SLC", "F0_SLC", "Tc_star_SLC")
#: Keys only the 2019 check reads.
KEYS_2019 = ("T1", "xi1", *SLC_KEYS)
SITE_KEYS = {"ag", "F0", "Tc_star", "soil", "topography", "FC", "q", "Z", "H", "storeys", "edition", *KEYS_2019}


def _positive(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value) and value > 0


@dataclass(frozen=True)
class Site:
    """A site's parameters (SPEC §3 site file): a_g in g, T_C* in s, Z and H in m (module docstring)."""

    ag: float
    F0: float
    Tc_star: float
    soil: str
    topography: str = "T1"
    #: Confidence factor: 1.35 (knowledge level LC1) unless the user's survey earns less.
    FC: float = 1.35
    #: Behaviour factor of the linear check: 2.0 as the Circolare sets it.
    q: float = 2.0
    Z: float = 0.0
    H: float | None = None
    storeys: int | None = None
    #: The Circolare whose form of the checks applies: "2019" or "2009".
    edition: str = EDITIONS[0]
    #: The main structure's first-mode period T_1 (s), 2019 at Z > 0; None: C₁ H^¾.
    T1: float | None = None
    #: The main structure's first-mode equivalent viscous damping ξ_1 (percent), 2019 at Z > 0.
    xi1: float | None = None
    #: a_g (in g), F₀ and T_C* (s) at the SLC's return period (2019's SLC check).
    ag_SLC: float | None = None
    F0_SLC: float | None = None
    Tc_star_SLC: float | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Site:
        """The site of a TOML table (keys of SPEC §3), checked key by key."""
        unknown = set(data) - SITE_KEYS
        if unknown:
            raise ValueError(f"site: unknown key(s) {sorted(unknown)}; allowed: {sorted(SITE_KEYS)}")
        missing = {"ag", "F0", "Tc_star", "soil"} - set(data)
        if missing:
            raise ValueError(f"site: missing key(s) {sorted(missing)}")
        values = dict(data)
        if isinstance(values.get("edition"), int) and not isinstance(values["edition"], bool):
            values["edition"] = str(values["edition"])  # edition = 2019 in TOML reads as a number
        site = cls(**values)
        site.check()
        return site

    def check(self) -> None:
        """Raise ValueError naming the first key whose value is out of its domain."""
        for name in ("ag", "F0", "Tc_star", "FC", "q"):
            value = getattr(self, name)
            if not _positive(value):
                raise ValueError(f"site: {name} must be a positive number, got {value!r}")
        Z = self.Z
        if isinstance(Z, bool) or not isinstance(Z, (int, float)) or not (math.isfinite(Z) and Z >= 0):
            raise ValueError(f"site: Z must be a number >= 0 (m), got {Z!r}")
        if Z > 0:
            if not (isinstance(self.H, (int, float)) and self.H >= Z and self.H > 0):
                raise ValueError(f"site: a mechanism at Z = {Z} m needs the building's height H >= Z (m)")
            n = self.storeys
            if not (isinstance(n, int) and not isinstance(n, bool) and n >= 1):
                raise ValueError("site: a mechanism at Z > 0 needs 'storeys', a positive integer")
        if self.edition not in EDITIONS:
            raise ValueError(f"site: edition must be one of {list(EDITIONS)}, got {self.edition!r}")
        elastic_spectrum(self.ag, self.F0, self.Tc_star, self.soil, self.topography)  # checks soil, topography
        self._check_2019_keys()

    def _check_2019_keys(self) -> None:
        for name in KEYS_2019:
            value = getattr(self, name)
            if value is not None and not _positive(value):
                raise ValueError(f"site: {name} must be a positive number, got {value!r}")
        given = [k for k in SLC_KEYS if getattr(self, k) is not None]
        if given and len(given) < len(SLC_KEYS):
            lacking = [k for k in SLC_KEYS if getattr(self, k) is None]
            raise ValueError(
                f"site: the SLC check needs the hazard at the SLC's return period: {given} given without {lacking}"
            )
        if given:
            ag, f0, tc = (float(getattr(self, k)) for k in SLC_KEYS)
            elastic_spectrum(ag, f0, tc, self.soil, self.topography)

    def needs_for(self, edition: str) -> None:
        """Raise ValueError when ``edition``'s check cannot run on this site (a key missing or
        one it does not read)."""
        if edition == "2009":
            extra = [k for k in KEYS_2019 if getattr(self, k) is not None]
            if extra:
                raise ValueError(f"site: {extra} are read by the 2019 check only; edition 2009 has no use for them")
        elif self.Z > 0 and self.xi1 is None:
            raise ValueError(
                f"edition 2019: a mechanism at Z > 0 needs 'xi1', the main structure's first-mode "
                f"equivalent viscous damping (percent; Circolare 2019 §C8.7.1.2.1.4: 10-20 % for masonry "
                f"at the ultimate limit state) for its floor acceleration (Eqs. C7.2.7-8); Z = {self.Z} m"
            )


def load_site(path: str | Path) -> Site:
    """Read a site file (TOML, SPEC §3)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except OSError as exc:
        raise ValueError(f"site file '{path}': cannot be read ({exc.strerror})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"site file '{path}': not valid TOML ({exc})") from exc
    try:
        return Site.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"site file '{path}': {exc}") from exc
