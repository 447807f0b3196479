"""The kinematic seismic check of local mechanisms (NTC 2018; Circolare 2019 §C8.7.1, or 2009 §C8A.4)."""

from alma.seismic.check import SeismicResult, seismic
from alma.seismic.site import EDITIONS, Site, load_site
from alma.seismic.spectrum import Spectrum, elastic_spectrum

__all__ = ["EDITIONS", "SeismicResult", "Site", "Spectrum", "elastic_spectrum", "load_site", "seismic"]
