// The MPI job a portcal process is a rank of, when it was started by
// `mpirun` or Slurm's `srun` (OpenMPI from Debian). A process started on
// its own is the one rank of a world of one, and MPI is never initialised:
// no MPI daemon is started for an ordinary run.
//
// Ranks agree through collective calls only (every rank makes the same
// calls in the same order); the files they share are on one file system
// (the database's folder).
#pragma once

#include <cstdint>
#include <string>

namespace portcal {

class MpiWorld {
 public:
  // Initialises MPI if this process is a rank of an MPI job (mpirun's or
  // srun's environment says so). Call once, first thing in main.
  static void Init(int* argc, char*** argv);
  // Finalises MPI if Init initialised it.
  static void Finalize();
  // Ends every rank of the job (MPI_Abort) with `code`: for a rank that
  // cannot go on while the others wait in a collective call.
  [[noreturn]] static void Abort(int code);

  static int Rank();  // 0 for a process on its own
  static int Size();  // 1 for a process on its own
  static bool Distributed() { return Size() > 1; }

  // True on every rank iff `ok` is true on every rank.
  static bool AllSucceeded(bool ok);
  // The sum over the ranks of `value`, on every rank.
  static int64_t Sum(int64_t value);
  // Waits for every rank.
  static void Barrier();
};

}  // namespace portcal
