"""Measured BRDFs: the CUReT database and any BRDF table, compared with the models (paper §5.3).

Loading::

    from roughscope import curet
    db = curet.load()                 # the shared data/curet (see find_directory)
    db.brdf.shape                     # (61, 205) BRDF values f in 1/sr (non-positive ones kept)
    db.brightness                     # f * cos(theta_i): camera-like brightness (§5.3)
    db.angles["theta_s_deg"]          # geometry in the paper's frame (degrees)

Comparing (Tables 3 and 4, Fig. 10)::

    r = curet.compare(25)             # dict: the same document as `roughscope curet --json --series`
    r["E1_over_E2"], r["sigma_over_T_gaussian"], r["sse"]["vh_exponential"]
    rows = curet.compare_all()        # every sample (list of dicts)

Angles are in degrees at this boundary. Errors raise roughscope.Error (a ValueError); a missing
database raises roughscope.DataError naming the files needed and where they come from.

Keys of a comparison: ``sample``, ``name``, ``channel``, ``measurements``, ``used``,
``E1_over_E2``, ``sigma_over_T_gaussian``, ``sigma_over_T_exponential`` (None when unavailable),
``two_point`` (details and the reason when unavailable), ``sse`` (the paper's Table-4 error per
model), ``rmse``, ``sse_gain`` (after the optimal gain), ``winner``, ``winner_paper_metric``,
``models`` (parameters, standard errors, fit status, method per model), ``data_issues`` and, with
``series=True``, ``series`` (per-measurement data and model brightness normalised by their maxima).
"""

import numpy as np

from . import _core

#: The Table-4 columns, in the paper's order.
PAPER_MODELS = (
    "oren_nayar",
    "lafortune",
    "bk_gaussian",
    "bk_exponential",
    "vh_gaussian",
    "vh_exponential",
)
#: Least-squares fits with an unknown gain.
FIT_MODELS = tuple(m + "_fit" for m in PAPER_MODELS)
MODELS = PAPER_MODELS + FIT_MODELS

#: The paper's labels.
LABELS = {
    "oren_nayar": "O–N",
    "lafortune": "LFTG",
    "bk_gaussian": "B–K(G)",
    "bk_exponential": "B–K(E)",
    "vh_gaussian": "V–H–B–K(G)",
    "vh_exponential": "V–H–B–K(E)",
}
LABELS.update({m + "_fit": LABELS[m] + " fit" for m in PAPER_MODELS})

#: The samples of the paper's Tables 3–4 and Fig. 10.
PAPER_SAMPLES = (25, 34, 41)


class CuretData:
    """The CUReT database for one channel, as numpy arrays."""

    def __init__(self, db):
        self._db = db
        self.directory = db.directory
        self.channel = db.channel
        #: sample numbers, int64, shape (n,)
        self.samples = db.samples
        #: BRDF values f (1/sr), shape (n, 205); column j is measurement j + 1
        self.brdf = db.brdf
        #: saturated-pixel fractions (same shape) or None when not published
        self.overflow = db.overflow
        #: table.txt in degrees plus the paper's frame (theta_s_deg, phi_s_deg)
        self.angles = db.angles_deg

    @property
    def brightness(self):
        """Camera-like brightness E = f cos(theta_i) (§5.3), shape (n, 205)."""
        return self.brdf * np.cos(np.radians(self.angles["theta_i_deg"]))[None, :]

    def row(self, sample):
        """Row index of `sample` (ValueError if absent)."""
        hits = np.nonzero(self.samples == sample)[0]
        if hits.size == 0:
            raise _core.InvalidArgument(
                f"sample = {sample} is not in the database (valid samples: "
                f"{int(self.samples.min())}..{int(self.samples.max())})"
            )
        return int(hits[0])

    def sample_table(self, sample):
        """One sample as a dict of numpy arrays (angles in degrees, paper frame included)."""
        return self._db.sample_table(int(sample))

    def nonpositive(self):
        """(sample, measurement, value) of every BRDF value <= 0."""
        rows, cols = np.nonzero(self.brdf <= 0)
        return [(int(self.samples[r]), int(c) + 1, float(self.brdf[r, c])) for r, c in zip(rows, cols)]

    def compare(self, sample, *, series=True, **options):
        """Compare every model with one sample; returns a dict (see the module docstring).

        Options: theta1_deg, theta2_deg (two-point angles; default from the table),
        pair=(81, 112), on_sigma_rad and on_albedo (given Oren–Nayar parameters; default for 25,
        34, 41: the paper's Table 3), fits=True, radiometry="radiance", max_overflow=None.
        """
        return self._db.compare(int(sample), series=series, **options)

    def compare_all(self, *, fits=True, radiometry="radiance", max_overflow=None, threads=0,
                    series=False):
        """Every sample: list of dicts in file order."""
        return self._db.compare_all(fits=fits, radiometry=radiometry, max_overflow=max_overflow,
                                    threads=threads, format="dict", series=series)

    def compare_all_text(self, format="markdown", *, fits=True, radiometry="radiance",
                         max_overflow=None, threads=0):
        """Every sample as CSV or Markdown text (the same as `roughscope curet --all`)."""
        return self._db.compare_all(fits=fits, radiometry=radiometry, max_overflow=max_overflow,
                                    threads=threads, format=format, series=False)


def find_directory(data_dir=None):
    """The CUReT directory: data_dir, else data/curet in the shared folder.

    The shared folder is found by the library's one rule (io/data_locator.hpp, also
    ``roughscope.curet_data_dir()``): $ROUGHSCOPE_SHARED_DIR when set, else ../shared searched
    upward from the current directory; the older $ROUGHSCOPE_CURET is the last resort. Raises
    roughscope.DataError naming the files needed and where they come from otherwise.
    """
    return _core.curet_find_directory(None if data_dir is None else str(data_dir))


def available(data_dir=None):
    """True when the CUReT files can be found (never raises)."""
    try:
        find_directory(data_dir)
        return True
    except _core.DataError:
        return False


def load(data_dir=None, channel="mean"):
    """Load the database (channel: mean, red, green, blue) as a :class:`CuretData`."""
    return CuretData(_core.curet_load(None if data_dir is None else str(data_dir), channel))


def compare(sample, data_dir=None, channel="mean", **options):
    """Load the database and compare every model with one sample (dict)."""
    return load(data_dir, channel).compare(sample, **options)


def compare_all(data_dir=None, channel="mean", **options):
    """Load the database and compare every sample (list of dicts)."""
    return load(data_dir, channel).compare_all(**options)


def read_brdf_csv(path, channel=None):
    """Read a BRDF table (CSV: theta_i, phi_i, theta_s, phi_s in degrees, value; optional weight,
    channel, measurement) into a dict of numpy arrays. theta_s/phi_s are the viewing direction
    with both azimuths in one sample frame; the paper's frame is added as theta_s_deg/phi_s_deg
    (phi_s = phi_v - phi_i + 180)."""
    return _core.brdf_read_csv(str(path), channel)


def compare_table(path=None, *, theta_i_deg=None, phi_i_deg=None, theta_s_deg=None,
                  phi_s_deg=None, value=None, weight=None, name="table", channel=None,
                  series=True, **options):
    """Compare every model with any BRDF table: a CSV file (path) or arrays (degrees, same frame
    as read_brdf_csv). Options as CuretData.compare. Returns a dict."""
    if path is not None:
        if value is not None:
            raise _core.InvalidArgument("give either a CSV path or arrays, not both")
        return _core.brdf_compare_csv(str(path), channel=channel, series=series, **options)
    if value is None:
        raise _core.InvalidArgument("give a CSV path or the arrays theta_i_deg, phi_i_deg, "
                                    "theta_s_deg, phi_s_deg and value")
    return _core.brdf_compare_arrays(
        np.asarray(theta_i_deg, float), np.asarray(phi_i_deg, float),
        np.asarray(theta_s_deg, float), np.asarray(phi_s_deg, float),
        np.asarray(value, float),
        weight=None if weight is None else np.asarray(weight, float),
        name=name, series=series, **options,
    )


def error_measures(model, data, weights=None):
    """The paper's Table-4 error sum((M/max M - d/max d)^2) ('sse'), 'rmse' = sqrt(sse/N), and
    'sse_gain' = min over K of sum((K M - d/max d)^2) with the optimal 'gain' K."""
    return _core.comparison_error_measures(
        np.asarray(model, float).ravel().tolist(),
        np.asarray(data, float).ravel().tolist(),
        None if weights is None else np.asarray(weights, float).ravel().tolist(),
    )


def sample_name(sample):
    """The paper's name of samples 25, 34, 41 ('' for the others)."""
    return _core.curet_sample_name(int(sample))


def paper_oren_nayar(sample):
    """(sigma_rad, albedo) of the paper's Table 3 for samples 25, 34, 41, else None."""
    return _core.curet_paper_oren_nayar(int(sample))
