/* SPDX-License-Identifier: MIT */
/* Tangled from literate/index.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/index.org::Umbrella Header][Umbrella Header]] */
#ifndef FOLDEST_H
#define FOLDEST_H

#define FE_VERSION "0.1.0"

#ifdef __cplusplus
extern "C" {
#endif

#include "foldest/error.h"
#include "foldest/fold.h"
#include "foldest/stream.h"
#include "foldest/meanvar.h"
#include "foldest/random.h"
#include "foldest/csv.h"
#include "foldest/special.h"
#include "foldest/discover.h"
#include "foldest/catalog.h"
#include "foldest/synth.h"
#include "foldest/model.h"
#include "foldest/dynamics.h"
#include "foldest/lsq.h"
#include "foldest/schur.h"
#include "foldest/lm.h"
#include "foldest/sessions.h"
#include "foldest/kalman.h"
#include "foldest/locate.h"
#include "foldest/expr.h"
#include "foldest/parallel.h"
#include "foldest/quadric.h"
#include "foldest/sphere.h"

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_H */
/* Umbrella Header ends here */
