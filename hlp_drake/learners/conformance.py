"""The scikit-learn estimator checks a learner is known to fail, declared by the learner itself.

scikit-learn >= 1.6 dropped the ``_xfail_checks`` tag; the supported way is the
``expected_failed_checks`` argument of ``check_estimator`` (a dict) and of
``parametrize_with_checks`` (a callable of the estimator, such as ``expected_failed_checks`` here).
"""

from __future__ import annotations

from sklearn.base import BaseEstimator

SAMPLE_WEIGHT_EQUIVALENCE = "check_sample_weight_equivalence_on_dense_data"


def expected_failed_checks(estimator: BaseEstimator) -> dict[str, str]:
    """``{check name: reason}`` as declared by the estimator's class (``EXPECTED_FAILED_CHECKS``)."""
    return dict(getattr(type(estimator), "EXPECTED_FAILED_CHECKS", {}))
