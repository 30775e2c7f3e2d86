// The claims' sizes found about the model they update, not as their first-order shadow: a film's
// change moves the temperatures its own load is formed on, heat that grows with temperature feeds
// back on itself, a conductivity changes the operator its response is marched with, and the first
// claim changes what the second's column should have been. The linearised fit of select_effects
// is the start of a Gauss–Newton refit whose every step marches the updated model.
#pragma once

#include "calibration/effects.hpp"
#include "calibration/model.hpp"
#include "core/case_spec.hpp"

namespace tt::calibration {

/// `sel` with its claims' shared parameters refitted together about the declared model updated
/// with every claim (docs/calibration.md, "Refit"). A Gauss–Newton step marches each training run
/// of `cat` on the updated model (its operators assembled again when a conductivity or capacity
/// changed), with the claims' unit loads as columns: the residual is that model's, the Jacobian
/// its tangent (heat that grows with temperature without its own feedback, so the step is a
/// fixed-point iteration there). It stops when every parameter moves by less than
/// options.refit_tolerance_sigmas of its standard error or options.refit_tolerance_rel of its
/// value, after at most options.refit_max_iterations steps; a step that raises the sum of
/// squares is halved, and so is one that leaves the physical bounds (unphysical_reason), up to
/// eight times: a claim whose step still leaves them "runs into the physical bounds". A claimed
/// per-run air is fitted on each run beside the shared parameters (its least squares on the run's
/// temperature rows eliminated from every step, then refitted within its bounds at the new
/// point); lags are held as fitted. Claims are refitted when one is not linear in
/// its parameter (nonlinear_in_parameter) or when there are two; otherwise `sel` is returned as it
/// is. A claim whose refitted value is unphysical is dropped from the claims (its `unphysical` says
/// why) and the rest are refitted again.
Selection refit_claimed(const MarchModel& model, const core::CaseSpec& declared,
                        const Catalogue& cat, Selection sel, const CalibrationOptions& options);

/// `fit` (a candidate of `cat` not linear in its parameter) sized alone about the declared model
/// updated with it, as refit_claimed does, from its linearised value halved towards zero until it
/// is physical (the linearisation overstates a film's or a feedback's size), with its secant
/// responses at that size. select_effects' Resizer.
Resized refit_alone(const MarchModel& model, const core::CaseSpec& declared, const Catalogue& cat,
                    const EffectFit& fit, const Eigen::VectorXd& sigma,
                    const CalibrationOptions& options);

}  // namespace tt::calibration
