"""Statistics of the paper's 108-panel design of experiments (Appendix A, Table 2).

``anova`` fits main effects and interactions of the four factors (panel ratio, block ratio,
bond type, friction) and returns the ANOVA table of Table 2; ``figures`` (imported on demand,
it needs matplotlib) draws Figures 5 to 10.
"""

from alma.stats.anova import (
    CHAIN_FACTOR,
    FACTOR_LEVELS,
    FACTORS,
    RESULT_COLUMNS,
    AnovaResult,
    AnovaRow,
    anova,
    default_factors,
    fit_model,
    load_results,
    press_balanced,
    press_from_leverage,
    r2_pred_balanced,
    varying_factors,
)
from alma.stats.effects import (
    StandardizedEffect,
    TukeyComparison,
    TukeyResult,
    equivalent_t,
    pareto_reference,
    standardized_effects,
    tukey_bond,
)

__all__ = [
    "CHAIN_FACTOR",
    "FACTORS",
    "FACTOR_LEVELS",
    "RESULT_COLUMNS",
    "AnovaResult",
    "AnovaRow",
    "StandardizedEffect",
    "TukeyComparison",
    "TukeyResult",
    "anova",
    "default_factors",
    "equivalent_t",
    "fit_model",
    "load_results",
    "pareto_reference",
    "press_balanced",
    "press_from_leverage",
    "r2_pred_balanced",
    "standardized_effects",
    "tukey_bond",
    "varying_factors",
]
