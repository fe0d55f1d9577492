#include "bench/models/error_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <ceres/ceres.h>
#include <fmt/format.h>

namespace depthbench {
namespace {

const ModelInfo kModels[] = {
    {ModelKind::kConstant, "constant", 1, false, false, {"a"}},
    {ModelKind::kDepth, "depth", 2, false, true, {"a", "c (bits per doubling of z/n)"}},
    {ModelKind::kRatio, "ratio", 2, true, false, {"a", "s (bits per doubling of f/n)"}},
    {ModelKind::kFull, "full", 3, true, true, {"a", "s (bits per doubling of f/n)", "c (bits per doubling of z/n)"}},
    {ModelKind::kPhysical,
     "physical",
     4,
     true,
     true,
     {"log2 alpha (arithmetic floor)", "log2(beta u_fmt / u)", "gamma (power of z/n)", "delta (power of f/n)"}},
};

// Robust loss scale, in bits: a quantile estimated from a band of samples
// moves by a few tenths of a bit; a point off by several bits is an
// outlier and should weigh little.
constexpr double kCauchyScale = 0.5;

template <class T>
T Exp2(const T& v) {
  using std::exp;
  return exp(v * T(M_LN2));
}
template <class T>
T Log2(const T& v) {
  using std::log;
  return log(v) / T(M_LN2);
}

// Predicted b for parameters p at (x, y).
template <class T>
T Predict(ModelKind kind, const T* p, double x, double y) {
  switch (kind) {
    case ModelKind::kConstant: return p[0];
    case ModelKind::kDepth: return p[0] + p[1] * y;
    case ModelKind::kRatio: return p[0] + p[1] * x;
    case ModelKind::kFull: return p[0] + p[1] * x + p[2] * y;
    case ModelKind::kPhysical: {
      // 0.5 log2(2^A + 2^B), evaluated as max + log2(1 + 2^-(|A - B|)).
      const T a = T(2.0) * p[0];
      const T b = T(2.0) * p[1] + T(2.0) * p[2] * y + T(2.0) * p[3] * x;
      const T high = a > b ? a : b;
      const T low = a > b ? b : a;
      return T(0.5) * (high + Log2(T(1.0) + Exp2(low - high)));
    }
  }
  return T(0.0);
}

struct Residual {
  ModelKind kind;
  FitPoint point;
  template <class T>
  bool operator()(T const* const* parameters, T* residual) const {
    residual[0] = Predict(kind, parameters[0], point.x, point.y) - T(point.b);
    return true;
  }
};

// Ordinary least squares of b on (1, x, y) columns the model uses: the
// starting point of the robust fits.
std::vector<double> LeastSquares(std::span<const FitPoint> points, bool use_x, bool use_y) {
  const int k = 1 + (use_x ? 1 : 0) + (use_y ? 1 : 0);
  double ata[3][3] = {}, atb[3] = {};
  for (const FitPoint& p : points) {
    double row[3] = {1.0, 0.0, 0.0};
    int c = 1;
    if (use_x) row[c++] = p.x;
    if (use_y) row[c++] = p.y;
    for (int i = 0; i < k; ++i) {
      atb[i] += row[i] * p.b;
      for (int j = 0; j < k; ++j) ata[i][j] += row[i] * row[j];
    }
  }
  // Gaussian elimination with partial pivoting on the k x k system.
  double m[3][4];
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) m[i][j] = ata[i][j];
    m[i][k] = atb[i];
  }
  for (int col = 0; col < k; ++col) {
    int pivot = col;
    for (int r = col + 1; r < k; ++r)
      if (std::fabs(m[r][col]) > std::fabs(m[pivot][col])) pivot = r;
    std::swap(m[col], m[pivot]);
    if (std::fabs(m[col][col]) < 1e-300) return std::vector<double>(k, 0.0);
    for (int r = 0; r < k; ++r) {
      if (r == col) continue;
      const double f = m[r][col] / m[col][col];
      for (int j = col; j <= k; ++j) m[r][j] -= f * m[col][j];
    }
  }
  std::vector<double> solution(k);
  for (int i = 0; i < k; ++i) solution[i] = m[i][k] / m[i][i];
  return solution;
}

std::vector<double> InitialGuess(std::span<const FitPoint> points, ModelKind kind) {
  switch (kind) {
    case ModelKind::kConstant: return LeastSquares(points, false, false);
    case ModelKind::kDepth: return LeastSquares(points, false, true);
    case ModelKind::kRatio: return LeastSquares(points, true, false);
    case ModelKind::kFull: return LeastSquares(points, true, true);
    case ModelKind::kPhysical: {
      const std::vector<double> full = LeastSquares(points, true, true);
      double floor = std::numeric_limits<double>::infinity();
      for (const FitPoint& p : points) floor = std::min(floor, p.b);
      return {floor, full[0], full[2], full[1]};
    }
  }
  return {};
}

}  // namespace

const ModelInfo& Info(ModelKind kind) { return kModels[static_cast<int>(kind)]; }

Expected<ModelKind> ParseModelKind(const std::string& name) {
  for (const ModelInfo& m : kModels)
    if (name == m.name) return m.kind;
  return InvalidArgument(fmt::format("unknown model '{}'; allowed: constant, depth, ratio, full, physical", name));
}

double FittedModel::Predict(double x, double y) const {
  return depthbench::Predict<double>(kind, parameters.data(), x, y);
}

double FittedModel::StandardError(int parameter) const {
  const int k = static_cast<int>(parameters.size());
  if (covariance.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(std::max(0.0, covariance[parameter * k + parameter]));
}

double FittedModel::Variance(std::span<const double> weights) const {
  const int k = static_cast<int>(parameters.size());
  if (covariance.empty()) return std::numeric_limits<double>::quiet_NaN();
  double v = 0.0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) v += weights[i] * weights[j] * covariance[i * k + j];
  return v;
}

Estimate EstimateOf(const FittedModel& model, const std::function<double(const FittedModel&)>& quantity,
                    double confidence) {
  Estimate e;
  e.value = quantity(model);
  std::vector<double> gradient(model.parameters.size());
  FittedModel shifted = model;
  for (std::size_t i = 0; i < gradient.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::fabs(model.parameters[i]));
    shifted.parameters[i] = model.parameters[i] + h;
    gradient[i] = (quantity(shifted) - e.value) / h;
    shifted.parameters[i] = model.parameters[i];
  }
  const int dof = std::max(1, model.points - static_cast<int>(model.parameters.size()));
  const double half = StudentT(confidence, dof) * std::sqrt(model.Variance(gradient));
  e.low = e.value - half;
  e.high = e.value + half;
  return e;
}

Expected<FittedModel> FitModel(std::span<const FitPoint> points, ModelKind kind) {
  const ModelInfo& info = Info(kind);
  const int n = static_cast<int>(points.size());
  if (n < info.parameters + 1) {
    return InvalidArgument(
        fmt::format("{} points are too few for the {} model ({} parameters)", n, info.name, info.parameters));
  }
  FittedModel fit;
  fit.kind = kind;
  fit.points = n;
  fit.parameters = InitialGuess(points, kind);

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(kCauchyScale);
  for (const FitPoint& p : points) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<Residual, 4>(new Residual{kind, p});
    cost->AddParameterBlock(info.parameters);
    cost->SetNumResiduals(1);
    problem.AddResidualBlock(cost, &loss, fit.parameters.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  fit.converged = summary.termination_type == ceres::CONVERGENCE;

  // The robust cost is 1/2 sum rho(r^2); rho caps what outliers add.
  fit.rss = 2.0 * summary.final_cost;
  const int dof = n - info.parameters;
  fit.sigma = std::sqrt(fit.rss / dof);
  // BIC for Gaussian residuals; a tiny floor keeps a perfect fit finite.
  fit.bic = n * std::log(std::max(fit.rss, 1e-18 * n) / n) + info.parameters * std::log(static_cast<double>(n));

  // Covariance of the parameters: Ceres gives (J^T J)^-1 for unit-variance
  // residuals; the residual variance scales it.
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.null_space_rank = -1;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks{{fit.parameters.data(), fit.parameters.data()}};
  if (covariance.Compute(blocks, &problem)) {
    fit.covariance.resize(static_cast<std::size_t>(info.parameters) * info.parameters);
    covariance.GetCovarianceBlock(fit.parameters.data(), fit.parameters.data(), fit.covariance.data());
    for (double& c : fit.covariance) c *= fit.sigma * fit.sigma;
  }
  return fit;
}

std::vector<FittedModel> FitAndRank(std::span<const FitPoint> points, std::span<const ModelKind> candidates) {
  std::vector<FittedModel> fits;
  for (ModelKind kind : candidates) {
    auto fit = FitModel(points, kind);
    if (fit.ok() && std::isfinite(fit->bic)) fits.push_back(std::move(*fit));
  }
  std::stable_sort(fits.begin(), fits.end(), [](const FittedModel& a, const FittedModel& b) { return a.bic < b.bic; });
  return fits;
}

double StudentT(double confidence, int dof) {
  // The standard normal quantile z, by bisection on erfc (exact to 1e-12).
  const double tail = (1.0 - confidence) / 2.0;
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / M_SQRT2) > tail ? lo : hi) = mid;
  }
  const double z = 0.5 * (lo + hi), v = std::max(1, dof);
  const double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4 * v) + (5 * z5 + 16 * z3 + 3 * z) / (96 * v * v) +
         (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * v * v * v);
}

}  // namespace depthbench
