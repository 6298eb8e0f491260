/* The built-in models, one line each: PERI_MODEL(id) names the descriptor PeriModel_<id> that
 * models/<file>.c defines. The order is the order of registration, in which the "unknown model"
 * message lists them. Included by models/registry.c with PERI_MODEL defined; no include guard. */
PERI_MODEL(PMB)
PERI_MODEL(NPMB)
PERI_MODEL(PDS)
PERI_MODEL(MPPD)
PERI_MODEL(Gerstle)
PERI_MODEL(Antiplane)
PERI_MODEL(AntiplaneOS)
PERI_MODEL(CPMB)
PERI_MODEL(LPS)
