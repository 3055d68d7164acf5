// bodypoint: a sweep across the processes of `mpirun -np N bodypoint sweep ...` (Open MPI's C API).
//
// Rank 0 hands out one unit at a time (a batch of vector lanes, or one task: sweep.hpp plan_units)
// to whichever rank asks (dynamic load balancing: a close
// encounter of a time-transformed method can cost a hundred times a far pass), runs tasks itself on
// its own worker threads between messages, gathers every row and writes the output and its journal.
// Every rank computes a task exactly as a single process would, so the CSV is the single-process CSV.
// Without MPI at build time (BODYPOINT_HAVE_MPI undefined) the functions say so.
#pragma once

#include "sweep.hpp"
#include "sweep_tasks.hpp"

#include <memory>
#include <string>
#include <vector>

namespace bodypoint::cli {

/// True when this process was started by an MPI launcher with more than one process.
bool launched_by_mpi();
/// This process's rank as the launcher says (0 when not launched by MPI): ranks other than 0 leave
/// error messages to rank 0, which has the same arguments.
int launcher_rank();

/// MPI_Init/MPI_Finalize for the lifetime of the object; rank() and size() of MPI_COMM_WORLD.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Rank 0 tells every rank whether to go on (a failure on rank 0 before the sweep stops them all).
  bool agree(bool go) const;

 private:
  int rank_ = 0, size_ = 1;
};

/// The rows of the whole sweep on rank 0 (by task index; the journal's rows are not run again), an
/// empty vector on the other ranks. control.threads is the number of worker threads on rank 0; the
/// other ranks run one unit at a time each.
std::vector<std::string> run_sweep_mpi(const MpiSession& mpi, const SweepSpec& spec, const SweepControl& control);

}  // namespace bodypoint::cli
