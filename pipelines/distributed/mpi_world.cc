#include "pipelines/distributed/mpi_world.h"

#include <mpi.h>

#include <cstdlib>

namespace portcal {

namespace {

bool initialized = false;
int rank = 0;
int size = 1;

// OpenMPI's mpirun, and PMI / PMIx launchers (Slurm's srun), set these in
// every rank's environment.
bool LaunchedAsRank() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"}) {
    if (std::getenv(variable) != nullptr) return true;
  }
  return false;
}

}  // namespace

void MpiWorld::Init(int* argc, char*** argv) {
  if (initialized || !LaunchedAsRank()) return;
  MPI_Init(argc, argv);
  initialized = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
}

void MpiWorld::Finalize() {
  if (!initialized) return;
  MPI_Finalize();
  initialized = false;
}

void MpiWorld::Abort(int code) {
  if (initialized) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

int MpiWorld::Rank() { return rank; }

int MpiWorld::Size() { return size; }

bool MpiWorld::AllSucceeded(bool ok) {
  if (!initialized) return ok;
  int local = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  return all != 0;
}

int64_t MpiWorld::Sum(int64_t value) {
  if (!initialized) return value;
  long long local = value, sum = 0;
  MPI_Allreduce(&local, &sum, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return sum;
}

void MpiWorld::Barrier() {
  if (initialized) MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace portcal
