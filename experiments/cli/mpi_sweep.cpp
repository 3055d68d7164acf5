// A sweep across MPI processes (mpi_sweep.hpp): rank 0 coordinates and computes, the others compute.
#include "process.hpp"
#include "mpi_sweep.hpp"

#include "bodypoint/threads.hpp"
#include "bodypoint/io.hpp"
#include "rows_file.hpp"
#include "sweep_tasks.hpp"

#include <chrono>
#include <cstdlib>
#include <deque>
#include <exception>
#include <iostream>
#include <mutex>
#include <thread>

#ifdef BODYPOINT_HAVE_MPI
#include <mpi.h>
#endif

namespace bodypoint::cli {

bool launched_by_mpi() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(var)) return std::atoi(v) > 1;
  return false;
}

int launcher_rank() {
  for (const char* var : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* v = std::getenv(var)) return std::atoi(v);
  return 0;
}

#ifndef BODYPOINT_HAVE_MPI

MpiSession::MpiSession() {
  throw Error("this bodypoint was built without MPI (install libopenmpi-dev and rebuild); run the sweep in one "
              "process, or in shards with --shard K/N and bodypoint merge");
}
MpiSession::~MpiSession() = default;
bool MpiSession::agree(bool go) const { return go; }
std::vector<std::string> run_sweep_mpi(const MpiSession&, const SweepSpec&, const SweepControl&) { return {}; }

#else

namespace {

constexpr int kTagRow = 1;   // rank r -> 0: "" (ready), "<index>\t<row>\n" per task of a finished unit, or
                             // "!<reason>" when the unit failed (rank 0 reports it and ends the sweep)
constexpr int kTagTask = 2;  // 0 -> rank r: the task indices of the next unit, or none (no more)
/// The coordinator polls for messages this often while rank 0's threads compute: short against a
/// task (milliseconds to seconds), long enough to leave the core to the computing threads.
constexpr auto kPoll = std::chrono::microseconds(500);

/// Rank 0's queue of units (plan_units: batches of vector lanes or single tasks) and its rows;
/// shared by the coordinator and the local worker threads.
class Board {
 public:
  Board(const SweepSpec& spec, const SweepControl& control) : control_(control), rows_(task_count(spec)) {
    std::vector<std::size_t> todo;
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      const auto* done = control.journal ? &control.journal->done() : nullptr;
      if (done && done->count(i)) rows_[i] = done->at(i);
      else todo.push_back(i);
    }
    total_ = todo.size();
    for (auto& unit : plan_units(spec, todo, control.simd)) queue_.push_back(std::move(unit));
  }
  /// The next unit, or none when there is none or a signal or an error stopped the sweep.
  std::vector<std::size_t> take() {
    std::lock_guard<std::mutex> g(mutex_);
    if (queue_.empty() || interrupted() || error_) return {};
    std::vector<std::size_t> unit = std::move(queue_.front());
    queue_.pop_front();
    return unit;
  }
  void finish(std::size_t i, std::string row) {
    std::lock_guard<std::mutex> g(mutex_);
    rows_[i] = std::move(row);
    if (control_.journal) control_.journal->append(i, rows_[i]);
    ++finished_;
    if (control_.progress) std::cerr << "\r" << finished_ << "/" << total_ << (finished_ == total_ ? "\n" : "") << std::flush;
  }
  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> g(mutex_);
    if (!error_) error_ = e;
  }
  std::vector<std::string> result() {
    if (error_) std::rethrow_exception(error_);
    return std::move(rows_);
  }

 private:
  const SweepControl& control_;
  std::vector<std::string> rows_;
  std::deque<std::vector<std::size_t>> queue_;
  std::size_t total_ = 0, finished_ = 0;
  std::mutex mutex_;
  std::exception_ptr error_;
};

/// Rank 0's main thread: answers each rank's message with its next task until every rank has had -1.
void coordinate(const MpiSession& mpi, Board& board) {
  for (int active = mpi.size() - 1; active > 0;) {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagRow, MPI_COMM_WORLD, &flag, &st);
    if (!flag) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    int len = 0;
    MPI_Get_count(&st, MPI_CHAR, &len);
    std::string msg(static_cast<std::size_t>(len), '\0');
    MPI_Recv(msg.data(), len, MPI_CHAR, st.MPI_SOURCE, kTagRow, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    try {
      if (!msg.empty() && msg.front() == '!')
        throw Error("rank " + std::to_string(st.MPI_SOURCE) + ": " + msg.substr(1));
      for (std::size_t from = 0, end; (end = msg.find('\n', from)) != std::string::npos; from = end + 1) {
        const std::size_t tab = msg.find('\t', from);
        board.finish(std::stoul(msg.substr(from, tab - from)), msg.substr(tab + 1, end - tab - 1));
      }
    } catch (...) {
      board.fail(std::current_exception());
    }
    const std::vector<std::size_t> unit = board.take();
    const std::vector<long> next(unit.begin(), unit.end());
    MPI_Send(next.data(), static_cast<int>(next.size()), MPI_LONG, st.MPI_SOURCE, kTagTask, MPI_COMM_WORLD);
    if (next.empty()) --active;
  }
}

/// A rank other than 0: asks for a unit, runs it, sends its rows with the next request.
void serve(const SweepSpec& spec, const MapPlan& plan) {
  std::string msg;
  for (;;) {
    MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kTagRow, MPI_COMM_WORLD);
    MPI_Status st;
    MPI_Probe(0, kTagTask, MPI_COMM_WORLD, &st);
    int count = 0;
    MPI_Get_count(&st, MPI_LONG, &count);
    std::vector<long> next(static_cast<std::size_t>(count));
    MPI_Recv(next.data(), count, MPI_LONG, 0, kTagTask, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (next.empty()) return;
    const std::vector<std::size_t> unit(next.begin(), next.end());
    msg.clear();
    try {
      const std::vector<std::string> rows = run_sweep_unit(spec, unit, &plan);
      for (std::size_t k = 0; k < unit.size(); ++k) msg += std::to_string(unit[k]) + "\t" + rows[k] + "\n";
    } catch (const std::exception& e) {  // this rank's error, for rank 0 to report: it alone prints
      msg = std::string("!") + e.what();
    }
  }
}

}  // namespace

MpiSession::MpiSession() {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

bool MpiSession::agree(bool go) const {
  int flag = go ? 1 : 0;
  MPI_Bcast(&flag, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return flag == 1;
}

std::vector<std::string> run_sweep_mpi(const MpiSession& mpi, const SweepSpec& spec, const SweepControl& control) {
  const CooperativeInterrupt stop_at_row_boundary;  // a signal stops the handing out of tasks
  // Every rank makes the map's plan (its pilots), so that auto's rows are the same whichever rank runs them.
  const MapPlan plan = plan_map(spec, std::max(1u, control.threads));
  if (mpi.rank() != 0) {
    serve(spec, plan);
    return {};
  }
  Board board(spec, control);
  auto worker = [&] {
    try {
      for (std::vector<std::size_t> unit; !(unit = board.take()).empty();) {
        const std::vector<std::string> rows = run_sweep_unit(spec, unit, &plan);
        for (std::size_t k = 0; k < unit.size(); ++k) board.finish(unit[k], rows[k]);
      }
    } catch (...) {
      board.fail(std::current_exception());
    }
  };
  {
    const WorkerThreads pool(std::max(1u, control.threads), worker);  // none: the other ranks do it all
    coordinate(mpi, board);
  }
  CooperativeInterrupt::check();
  return board.result();
}

#endif

}  // namespace bodypoint::cli
