// SPDX-License-Identifier: MIT
// The QR route of ConnectionSolver (src/connection/qr_engine.h).
#include "connection/qr_engine.h"

#include <Eigen/Dense>
#include <SuiteSparseQR.hpp>
#include <string>
#include <vector>

#include "linalg/cholmod.h"
#include "linalg/timing.h"
#include "trivcon/error.h"

namespace trivcon::connection {

namespace {

class QREngine : public SolverEngine {
 public:
  mutable linalg::CholmodLongContext cc_;
  cholmod_common& cc() const { return *cc_; }
  SuiteSparseQR_factorization<double>* qr = nullptr;
  Eigen::VectorXd sqrt_w;
  int nD = 0, nC = 0, m = 0;
  Eigen::MatrixXd responses;  // y for each unit C right-hand side (m × nC)
  Eigen::MatrixXd P;
  std::string ordering() const override { return "SuiteSparseQR default"; }

  Eigen::VectorXd apply_P(const Eigen::VectorXd& v) const override { return P * v; }
  Eigen::VectorXd P_column(int i) const override { return P.col(i); }
  Eigen::MatrixXd dense_P() const override { return P; }
  Eigen::MatrixXd P_lower;  // P = P_lowerᵀ P_lower
  const Eigen::MatrixXd& P_factor(bool& lower) const override {
    lower = true;
    return P_lower;
  }

  QREngine(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w, SetupTimings& timings) {
    try {
      set_up(Dt, Ct, w, timings);
    } catch (...) {  // the destructor does not run for an object whose constructor throws
      release();
      throw;
    }
  }
  ~QREngine() override { release(); }
  void release() {
    if (qr) SuiteSparseQR_free<double>(&qr, &cc());
  }
  void set_up(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w, SetupTimings& timings) {
    auto t0 = linalg::Clock::now();
    sqrt_w = w.cwiseSqrt();
    nD = static_cast<int>(Dt.cols()), nC = static_cast<int>(Ct.cols()), m = static_cast<int>(Dt.rows());
    Eigen::SparseMatrix<double, Eigen::ColMajor, SuiteSparse_long> At(m, nD + nC);  // (A W^½)ᵀ
    {
      std::vector<Eigen::Triplet<double, SuiteSparse_long>> trip;
      for (int k = 0; k < Dt.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(Dt, k); it; ++it) trip.emplace_back(it.row(), k, it.value() * sqrt_w(it.row()));
      for (int k = 0; k < Ct.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(Ct, k); it; ++it) trip.emplace_back(it.row(), nD + k, it.value() * sqrt_w(it.row()));
      At.setFromTriplets(trip.begin(), trip.end());
      At.makeCompressed();
    }
    timings.assemble += linalg::seconds_since(t0);
    t0 = linalg::Clock::now();
    cholmod_sparse A = linalg::sparse_view(At);
    qr = SuiteSparseQR_factorize<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, &A, &cc());
    if (!qr || cc().status != CHOLMOD_OK) throw Error("SuiteSparseQR could not factor the constraint matrix");
    if (cc().SPQR_istat[4] < nD + nC)
      throw Error("the constraint matrix is rank deficient (rank " + std::to_string(cc().SPQR_istat[4]) + " of " + std::to_string(nD + nC) +
                  "); try --weights unit");
    timings.factor += linalg::seconds_since(t0);
    t0 = linalg::Clock::now();
    responses.resize(m, nC);
    for (int c = 0; c < nC; ++c) {
      Eigen::VectorXd b = Eigen::VectorXd::Zero(nD + nC);
      b(nD + c) = 1;
      responses.col(c) = min_norm_y(b);
    }
    P = responses.transpose() * responses;
    P_diagonal_ = P.diagonal();
    if (nC > 0) {
      // P = Tᵀ T with T lower triangular, as the Cholesky route has it (R_CC⁻¹): the Cholesky factor of P
      // with rows and columns reversed, reversed back.
      const Eigen::MatrixXd reversed = P.reverse();
      Eigen::LLT<Eigen::MatrixXd> llt(reversed);
      if (llt.info() != Eigen::Success) throw Error("the cycle rows of the constraint system are dependent; try --weights unit");
      P_lower = Eigen::MatrixXd(llt.matrixU()).reverse();
    }
    timings.schur += linalg::seconds_since(t0);
  }
  Eigen::VectorXd min_norm_y(const Eigen::VectorXd& b) const {
    cholmod_dense* B = cholmod_l_allocate_dense(b.size(), 1, b.size(), CHOLMOD_REAL, &cc());
    std::copy(b.data(), b.data() + b.size(), static_cast<double*>(B->x));
    cholmod_dense* Z = SuiteSparseQR_solve<double>(SPQR_RTX_EQUALS_ETB, qr, B, &cc());
    cholmod_dense* X = Z ? SuiteSparseQR_qmult<double>(SPQR_QX, qr, Z, &cc()) : nullptr;
    if (!X) throw Error("SuiteSparseQR solve failed");
    Eigen::VectorXd y = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(X->x), m);
    cholmod_l_free_dense(&B, &cc()), cholmod_l_free_dense(&Z, &cc()), cholmod_l_free_dense(&X, &cc());
    return y;
  }
  // With (A W^½)ᵀ E = Q R: A W Aᵀ = E Rᵀ R Eᵀ and A x = E Rᵀ (Qᵀ W^-½ x) restricted to R's rows, so
  // y = E R⁻¹ (Qᵀ W^-½ x).
  Eigen::VectorXd multipliers(const Eigen::VectorXd& x) const override {
    const int n = nD + nC;
    if (n == 0) return Eigen::VectorXd();
    cholmod_dense* B = cholmod_l_allocate_dense(m, 1, m, CHOLMOD_REAL, &cc());
    Eigen::Map<Eigen::VectorXd>(static_cast<double*>(B->x), m) = x.cwiseQuotient(sqrt_w);
    cholmod_dense* Z = SuiteSparseQR_qmult<double>(SPQR_QTX, qr, B, &cc());
    cholmod_dense* Y = Z ? SuiteSparseQR_solve<double>(SPQR_RETX_EQUALS_B, qr, Z, &cc()) : nullptr;
    if (!Y) {
      cholmod_l_free_dense(&B, &cc()), cholmod_l_free_dense(&Z, &cc());
      throw Error("SuiteSparseQR solve failed");
    }
    Eigen::VectorXd y = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(Y->x), n);
    cholmod_l_free_dense(&B, &cc()), cholmod_l_free_dense(&Z, &cc()), cholmod_l_free_dense(&Y, &cc());
    return y;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const override {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nD + nC);
    b.head(nD) = b_D;
    if (nC > 0) {
      // The energy is ‖y‖²; its gradient in b_C at b_C = 0 is 2 λ_C = 2 responsesᵀ y.
      const Eigen::VectorXd gradient = responses.transpose() * min_norm_y(b);
      b.tail(nC) = choose(-P.ldlt().solve(gradient));
    }
    return sqrt_w.asDiagonal() * min_norm_y(b);
  }
};

}  // namespace

std::unique_ptr<SolverEngine> make_qr_engine(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w,
                                             SetupTimings& timings) {
  return std::make_unique<QREngine>(Dt, Ct, w, timings);
}

}  // namespace trivcon::connection
