// Error models: how the error of a cell grows with the far/near ratio and
// with eye depth, fitted with Ceres.
//
// The quantity fitted is b = log2(relative error) + 24, "bits lost" before
// the floor at zero (so that small errors keep their information). The
// covariates are x = log2(far/near) and y = log2(eye depth / near). The
// family is nested, from the simplest:
//   constant   b = a
//   depth      b = a + c y                 (infinite far: no x exists)
//   ratio      b = a + s x
//   full       b = a + s x + c y
//   physical   rel = sqrt((alpha u)^2 + (beta u_fmt (z/n)^gamma (f/n)^delta)^2),
//              u = 2^-24: an arithmetic floor plus a storage term that grows
//              as a power of depth and ratio; in bits,
//              b = 0.5 log2(2^(2 p0) + 2^(2 p1 + 2 gamma y + 2 delta x)),
//              p0 = log2 alpha, p1 = log2(beta u_fmt / u).
// A robust (Cauchy) loss keeps a few outlying points from steering a fit;
// parameter uncertainty comes from ceres::Covariance, scaled by the
// residual variance; models are compared by BIC, so a term the data do not
// need is dropped.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"

namespace depthbench {

enum class ModelKind { kConstant, kDepth, kRatio, kFull, kPhysical };
inline constexpr ModelKind kAllModels[] = {ModelKind::kConstant, ModelKind::kDepth, ModelKind::kRatio, ModelKind::kFull,
                                           ModelKind::kPhysical};

struct ModelInfo {
  ModelKind kind;
  const char* name;
  int parameters;
  bool uses_ratio;
  bool uses_depth;
  std::vector<const char*> parameter_names;
};
const ModelInfo& Info(ModelKind kind);
Expected<ModelKind> ParseModelKind(const std::string& name);

// One observation: a quantile of the error in a set of samples that share
// a far/near ratio (x) and lie around an eye depth (y).
struct FitPoint {
  double x = 0.0;  // log2(far/near); ignored by models that do not use it
  double y = 0.0;  // log2(eye depth / near)
  double b = 0.0;  // log2(relative error) + 24
};

struct FittedModel {
  ModelKind kind = ModelKind::kConstant;
  std::vector<double> parameters;
  std::vector<double> covariance;  // row-major, parameters x parameters (empty if not computable)
  int points = 0;
  double rss = 0.0;    // sum of squared residuals, bits^2 (outliers capped by the robust loss)
  double sigma = 0.0;  // residual standard deviation, bits
  double bic = 0.0;
  bool converged = false;

  double Predict(double x, double y) const;
  // Standard error of a parameter.
  double StandardError(int parameter) const;
  // Variance of a linear combination sum w_i p_i of the parameters.
  double Variance(std::span<const double> weights) const;
};

// A quantity derived from a fitted model, with its confidence interval.
struct Estimate {
  double value = 0.0, low = 0.0, high = 0.0;
};
// Any function of a model's parameters (a prediction, a slope) with its
// two-sided interval at `confidence`: the delta method (the function's
// gradient by forward differences, the parameter covariance, Student's t
// on the fit's residual degrees of freedom). Without a covariance the
// interval is NaN.
Estimate EstimateOf(const FittedModel& model, const std::function<double(const FittedModel&)>& quantity,
                    double confidence = 0.95);

// Fits one model. Fails when there are fewer points than parameters + 1.
Expected<FittedModel> FitModel(std::span<const FitPoint> points, ModelKind kind);

// Fits every candidate and returns them ordered by BIC (best first).
// Candidates that cannot be fitted are left out.
std::vector<FittedModel> FitAndRank(std::span<const FitPoint> points, std::span<const ModelKind> candidates);

// Two-sided Student-t quantile for `confidence` (e.g. 0.95) and `dof`
// degrees of freedom (Cornish-Fisher expansion: good to 1e-3 for dof >= 3).
double StudentT(double confidence, int dof);

}  // namespace depthbench
