/* The built-in analyses, one line each: PERI_ANALYSIS(id) names the descriptor PeriAnalysis_<id>
 * that src/analysis/<file>.c defines. The order is the order of registration, in which the
 * "unknown analysis" message lists them. Included by src/analysis/analysis_registry.c with PERI_ANALYSIS
 * defined; no include guard. */
PERI_ANALYSIS(Static)
PERI_ANALYSIS(Modal)
PERI_ANALYSIS(Quasistatic)
PERI_ANALYSIS(Setup)
PERI_ANALYSIS(Anisotropy)
PERI_ANALYSIS(Dynamic)
PERI_ANALYSIS(Tune)
