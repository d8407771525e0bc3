// tests/test_snapshot_file.cpp: the HDF5 snapshot file (rbc::SnapshotFile) and the snapshot-matrix
// import. Create, write 3 of 5 snapshots (+ extra arrays), close; restart: the 3 are done; write the
// rest; ReadAll == what was written, bit for bit; rewrite of a done snapshot; a bad Write fails on
// every rank; a header with another mesh checksum / parameter box refuses the restart; a garbage
// file and an HDF5 file of another kind are refused; a restart without a file creates it; an
// existing file without restart is replaced; no *.tmp.* files are left. A writer killed without
// closing (fork on rank 0, two snapshots, _exit(9)) leaves a file that restarts with exactly those
// two done and readable; a writer killed by SIGKILL at an arbitrary moment of a loop of rewrites
// leaves a file that reopens, every done row complete. ImportSnapshotMatrix: HDF5 (rows = dofs,
// and -import_transpose), PETSc binary dense and AIJ, and its errors. A version-1 file (dense contact matrices in
// the extras contact_K, contact_dofs) is read without them and upgraded by a restart; an unknown version is refused.
// Scratch files live in /tmp/rbc_test_snapshot_file.<pid>.
#include "rbcontact/snapshot_file.hpp"
#include <hdf5.h>
#include <petscmat.h>
#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

using namespace rbc;

static int         failures = 0;
static PetscMPIInt rank     = 0;

static void Check(bool ok, const std::string &what)
{
  if (!ok) ++failures;
  if (rank == 0 || !ok) std::printf("  [%d] %-5s %s\n", rank, ok ? "ok" : "FAIL", what.c_str());
  std::fflush(stdout);
}

static bool SameBits(const std::vector<PetscReal> &a, const std::vector<PetscReal> &b)
{
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(PetscReal)) == 0);
}

static SnapshotHeader MakeHeader()
{
  SnapshotHeader h;
  h.scene        = "unit_square";
  h.optionsText  = "-mesh_file meshes/unit.geo -mu_names E,load\n-mu_min 1,0.95 -mu_max 2,1.15\n";
  h.sceneHash    = 0x0123456789abcdefULL;
  h.meshChecksum = 0xfedcba9876543210ULL; // > 2^63: must survive as uint64
  h.codeVersion  = "0.1.0-test";
  h.paramNames   = {"E", "load"};
  h.paramMin     = {1.0, 0.95};
  h.paramMax     = {2.0, 1.15};
  for (int i = 0; i < 5; ++i) h.trainingPoints.push_back({1.0 + 0.25 * i, 0.95 + 0.05 * i});
  h.ndofs = 11;
  h.nmult = 4;
  return h;
}

// Deterministic snapshot i (values that are not "nice" in binary, including a denormal and -0).
static Snapshot MakeSnapshot(const SnapshotHeader &h, PetscInt i, double salt = 0)
{
  Snapshot s;
  s.index = i;
  s.mu    = h.trainingPoints[i];
  for (PetscInt k = 0; k < h.ndofs; ++k) s.u.push_back(std::sin(1.0 + 7.0 * i + k + salt) / 3.0);
  s.u[0] = i == 2 ? 4.9e-324 : -0.0;
  for (PetscInt k = 0; k < h.nmult; ++k) s.lambda.push_back(std::exp(-0.1 * k - i) * (k % 2 ? 1 : 0) + salt);
  s.kacanovIterations = 3 + i;
  s.kkt               = {1e-10 * (i + 1), 2e-11 / 3.0, 3e-12 * std::sqrt(2.0 + i), 1e-9 / 7.0};
  s.seconds           = 0.125 * (i + 1) + salt;
  s.extra["gap"]      = {0.1 * i, -0.2 / 3.0, 0.3};
  s.extra["active"]   = {1.0 * (i % 2), 0.0};
  return s;
}

static bool SameSnapshot(const Snapshot &a, const Snapshot &b)
{
  if (a.index != b.index || !SameBits(a.mu, b.mu) || !SameBits(a.u, b.u) || !SameBits(a.lambda, b.lambda) || !SameBits(a.kkt, b.kkt)) return false;
  if (a.kacanovIterations != b.kacanovIterations || std::memcmp(&a.seconds, &b.seconds, sizeof a.seconds) != 0) return false;
  if (a.extra.size() != b.extra.size()) return false;
  for (const auto &kv : a.extra) {
    const auto it = b.extra.find(kv.first);
    if (it == b.extra.end() || !SameBits(kv.second, it->second)) return false;
  }
  return true;
}

// The specific message of the last error (PetscErrorMessage).
static std::string LastError(PetscErrorCode code)
{
  char *specific = NULL;
  if (PetscErrorMessage(code, NULL, &specific) || !specific) return std::string();
  return specific;
}

static void CheckError(PetscErrorCode code, const std::string &what, const std::vector<std::string> &needles)
{
  const std::string msg = code ? LastError(code) : std::string();
  bool              ok  = code != 0;
  for (const auto &n : needles) ok = ok && msg.find(n) != std::string::npos;
  Check(ok, what + " -> " + (code ? "error: " + msg : std::string("no error")));
}

static std::vector<std::string> TmpLeftovers(const std::string &dir)
{
  std::vector<std::string> out;
  if (DIR *d = opendir(dir.c_str())) {
    while (dirent *e = readdir(d))
      if (std::strstr(e->d_name, ".tmp.")) out.push_back(e->d_name);
    closedir(d);
  }
  return out;
}

static PetscErrorCode ReadAllChecked(const std::string &path, const SnapshotHeader &h, const std::vector<PetscInt> &expect, const std::string &what)
{
  std::vector<Snapshot> snaps;

  PetscFunctionBeginUser;
  PetscCall(SnapshotFile::ReadAll(path, &snaps));
  bool ok = snaps.size() == expect.size();
  for (size_t k = 0; ok && k < snaps.size(); ++k) ok = SameSnapshot(snaps[k], MakeSnapshot(h, expect[k]));
  Check(ok, what + ": ReadAll returns " + std::to_string(snaps.size()) + " snapshots, equal bit for bit");
  // Readers do not lock: without the barrier rank 0 could already be writing the next run.
  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  PetscFunctionReturn(0);
}

// Rank 0 forks a writer that stores snapshots 1 and 3 and dies with _exit(9) without closing.
static PetscErrorCode KilledWriter(const std::string &path, const SnapshotHeader &h)
{
  int status = -1;

  PetscFunctionBeginUser;
  if (rank == 0) {
    std::remove(path.c_str());
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = fork();
    PetscCheck(pid >= 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "fork failed");
    if (pid == 0) {
      // Child: the file through the API on PETSC_COMM_SELF (no communication).
      SnapshotFile f;
      if (f.Open(PETSC_COMM_SELF, path, h, false)) _exit(2);
      if (f.Write(MakeSnapshot(h, 1))) _exit(3);
      if (f.Write(MakeSnapshot(h, 3))) _exit(4);
      _exit(9); // killed: no Close, no destructor, no atexit handlers
    }
    if (waitpid(pid, &status, 0) != pid) status = -1;
  }
  PetscCallMPI(MPI_Bcast(&status, 1, MPI_INT, 0, PETSC_COMM_WORLD));
  Check(status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 9, "killed writer: child wrote 2 snapshots and died with _exit(9) (status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  SnapshotFile          f;
  std::vector<PetscInt> done;
  PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true));
  PetscCall(f.DoneIndices(&done));
  Check(done == std::vector<PetscInt>{1, 3}, "killed writer: restart finds exactly snapshots 1 and 3 done");
  PetscCall(f.Close());
  PetscCall(ReadAllChecked(path, h, {1, 3}, "killed writer"));
  // The restarted run completes the set.
  PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true));
  for (PetscInt i : {0, 2, 4}) PetscCall(f.Write(MakeSnapshot(h, i)));
  PetscCall(f.Close());
  PetscCall(ReadAllChecked(path, h, {0, 1, 2, 3, 4}, "killed writer, then completed"));

  // SIGKILL at an arbitrary moment of a writer that rewrites the snapshots in a loop, alternating
  // two versions: the file reopens, and every done row is one complete version, never a mix.
  for (int round = 0; round < 3; ++round) {
    int status = -1;
    if (rank == 0) {
      std::remove(path.c_str());
      int fds[2];
      PetscCheck(pipe(fds) == 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "pipe failed");
      std::fflush(stdout);
      std::fflush(stderr);
      const pid_t pid = fork();
      PetscCheck(pid >= 0, PETSC_COMM_SELF, PETSC_ERR_SYS, "fork failed");
      if (pid == 0) {
        SnapshotFile f;
        close(fds[0]);
        if (f.Open(PETSC_COMM_SELF, path, h, false)) _exit(2);
        if (write(fds[1], "x", 1) != 1) _exit(3); // created: the parent may kill us now
        for (long c = 0;; ++c)
          for (PetscInt i = 0; i < 5; ++i)
            if (f.Write(MakeSnapshot(h, i, (double)(c % 2)))) _exit(4);
      }
      close(fds[1]);
      char x = 0;
      const bool ready = read(fds[0], &x, 1) == 1;
      close(fds[0]);
      usleep(ready ? (useconds_t)(10000 + 47911 * round) : 0);
      kill(pid, SIGKILL);
      if (waitpid(pid, &status, 0) != pid) status = -1;
      if (!ready) status = -1;
    }
    PetscCallMPI(MPI_Bcast(&status, 1, MPI_INT, 0, PETSC_COMM_WORLD));
    Check(status != -1 && WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL, "SIGKILL round " + std::to_string(round) + ": writer killed mid-run");
    SnapshotFile          f;
    std::vector<PetscInt> done;
    std::vector<Snapshot> snaps;
    PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true));
    PetscCall(f.DoneIndices(&done));
    PetscCall(f.Close());
    PetscCall(SnapshotFile::ReadAll(path, &snaps));
    bool ok = snaps.size() == done.size();
    for (size_t k = 0; ok && k < snaps.size(); ++k) ok = snaps[k].index == done[k] && (SameSnapshot(snaps[k], MakeSnapshot(h, done[k], 0.0)) || SameSnapshot(snaps[k], MakeSnapshot(h, done[k], 1.0)));
    Check(ok, "SIGKILL round " + std::to_string(round) + ": file reopens with restart, " + std::to_string(done.size()) + " done snapshots, each complete");
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  }
  PetscFunctionReturn(0);
}

// Writes the HDF5 and PETSc binary test matrices (rank 0) and checks the import on every rank.
static PetscErrorCode TestImport(const std::string &dir)
{
  const PetscInt                      m = 6, n = 4; // dofs x snapshots
  std::vector<std::vector<PetscReal>> expect(n, std::vector<PetscReal>(m)), cols;
  const std::string                   h5 = dir + "/matrix.h5", dense = dir + "/dense.bin", aij = dir + "/aij.bin", garbage = dir + "/garbage.bin";
  PetscErrorCode                      code;

  PetscFunctionBeginUser;
  for (PetscInt j = 0; j < n; ++j)
    for (PetscInt i = 0; i < m; ++i) expect[j][i] = (i + j) % 3 ? std::cos(1.0 + i + 10.0 * j) : 0.0;
  if (rank == 0) {
    // HDF5: /S (m x n, rows = dofs), /group/ST (n x m), /vector (1D), /text (string).
    std::vector<double> S(m * n), ST(n * m);
    for (PetscInt i = 0; i < m; ++i)
      for (PetscInt j = 0; j < n; ++j) S[i * n + j] = ST[j * m + i] = expect[j][i];
    hid_t   f = H5Fcreate(h5.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t   g = H5Gcreate2(f, "/group", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hsize_t d1[2] = {(hsize_t)m, (hsize_t)n}, d2[2] = {(hsize_t)n, (hsize_t)m}, d3[1] = {5};
    hid_t   s1 = H5Screate_simple(2, d1, NULL), s2 = H5Screate_simple(2, d2, NULL), s3 = H5Screate_simple(1, d3, NULL);
    hid_t   a  = H5Dcreate2(f, "/S", H5T_IEEE_F64LE, s1, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t   b  = H5Dcreate2(f, "/group/ST", H5T_IEEE_F64LE, s2, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t   c  = H5Dcreate2(f, "/vector", H5T_IEEE_F64LE, s3, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    bool    ok = f >= 0 && g >= 0 && a >= 0 && b >= 0 && c >= 0;
    ok         = ok && H5Dwrite(a, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, S.data()) >= 0 && H5Dwrite(b, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, ST.data()) >= 0;
    ok         = ok && H5Dwrite(c, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, S.data()) >= 0;
    H5Dclose(a); H5Dclose(b); H5Dclose(c); H5Sclose(s1); H5Sclose(s2); H5Sclose(s3); H5Gclose(g);
    ok = H5Fclose(f) >= 0 && ok;
    PetscCheck(ok, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "test: cannot write %s", h5.c_str());
    // PETSc binary: a dense and an AIJ matrix.
    Mat         A, B;
    PetscViewer v;
    PetscCall(MatCreateSeqDense(PETSC_COMM_SELF, m, n, NULL, &A));
    PetscCall(MatCreateSeqAIJ(PETSC_COMM_SELF, m, n, n, NULL, &B));
    for (PetscInt i = 0; i < m; ++i)
      for (PetscInt j = 0; j < n; ++j) {
        PetscCall(MatSetValue(A, i, j, expect[j][i], INSERT_VALUES));
        if (expect[j][i] != 0.0) PetscCall(MatSetValue(B, i, j, expect[j][i], INSERT_VALUES));
      }
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
    PetscCall(PetscViewerBinaryOpen(PETSC_COMM_SELF, dense.c_str(), FILE_MODE_WRITE, &v));
    PetscCall(PetscViewerPushFormat(v, PETSC_VIEWER_NATIVE)); // the dense binary layout
    PetscCall(MatView(A, v));
    PetscCall(PetscViewerPopFormat(v));
    PetscCall(PetscViewerDestroy(&v));
    PetscCall(PetscViewerBinaryOpen(PETSC_COMM_SELF, aij.c_str(), FILE_MODE_WRITE, &v));
    PetscCall(MatView(B, v));
    PetscCall(PetscViewerDestroy(&v));
    PetscCall(MatDestroy(&A));
    PetscCall(MatDestroy(&B));
    std::ofstream(garbage) << "this is not a matrix\n";
    // Corrupt headers (audit of 2026-12-04): an AIJ file of 4 kB declaring 1000 x (2^31 - 1) with no nonzeros (its
    // dense import asked for 17 TB), and a dense one declaring (2^31 - 1)^2 (M * N * 8 overflowed 64 bits and passed).
    auto header = [](std::ofstream &o, std::vector<long long> words) {
      for (long long w : words)
        for (int b = (int)sizeof(PetscInt) - 1; b >= 0; --b) o.put((char)((unsigned long long)w >> (8 * b) & 0xff));
    };
    std::ofstream wide(dir + "/wide.bin", std::ios::binary), huge(dir + "/huge.bin", std::ios::binary);
    header(wide, {MAT_FILE_CLASSID, 1000, 2147483647LL, 0});
    header(wide, std::vector<long long>(1000, 0));
    header(huge, {MAT_FILE_CLASSID, 2147483647LL, 2147483647LL, -1});
    header(huge, std::vector<long long>(64, 0));
  }
  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));

  auto equal = [&](const std::vector<std::vector<PetscReal>> &c) {
    if (c.size() != expect.size()) return false;
    for (size_t j = 0; j < c.size(); ++j)
      if (!SameBits(c[j], expect[j])) return false;
    return true;
  };
  PetscCall(ImportSnapshotMatrix(PETSC_COMM_WORLD, h5 + ":/S", &cols));
  Check(equal(cols), "import HDF5 file.h5:/S (rows = dofs): 4 snapshots of 6 dofs");
  PetscCall(PetscOptionsSetValue(NULL, "-import_transpose", "1"));
  PetscCall(ImportSnapshotMatrix(PETSC_COMM_WORLD, h5 + ":/group/ST", &cols));
  Check(equal(cols), "import HDF5 file.h5:/group/ST with -import_transpose (rows = snapshots)");
  PetscCall(PetscOptionsClearValue(NULL, "-import_transpose"));
  PetscCall(ImportSnapshotMatrix(PETSC_COMM_WORLD, dense, &cols));
  Check(equal(cols), "import PETSc binary dense Mat");
  PetscCall(ImportSnapshotMatrix(PETSC_COMM_WORLD, aij, &cols));
  Check(equal(cols), "import PETSc binary AIJ Mat (converted to dense)");

  PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, h5 + ":/nope", &cols);
  CheckError(code, "import of a missing dataset", {h5, "/nope"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, h5 + ":/vector", &cols);
  CheckError(code, "import of a 1D dataset", {h5, "/vector", "2D"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, h5, &cols);
  CheckError(code, "import of an HDF5 file without a dataset name", {h5, ":/path/to/dataset"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, garbage, &cols);
  CheckError(code, "import of a garbage file", {garbage, "PETSc binary Mat"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, dir + "/wide.bin", &cols);
  CheckError(code, "import of an AIJ file whose dense copy exceeds the memory", {dir + "/wide.bin", "1000 x 2147483647", "more than this machine's memory"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, dir + "/huge.bin", &cols);
  CheckError(code, "import of a dense file whose size overflows 64 bits", {dir + "/huge.bin", "2147483647 x 2147483647", "truncated or corrupt"});
  code = ImportSnapshotMatrix(PETSC_COMM_WORLD, dir + "/missing.h5:/S", &cols);
  CheckError(code, "import of a missing file", {dir + "/missing.h5", "does not exist"});
  PetscCall(PetscPopErrorHandler());
  PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
  PetscErrorCode code;

  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
  long pid = (long)getpid();
  PetscCallMPI(MPI_Bcast(&pid, 1, MPI_LONG, 0, PETSC_COMM_WORLD));
  const std::string dir = "/tmp/rbc_test_snapshot_file." + std::to_string(pid);
  if (rank == 0) PetscCheck(mkdir(dir.c_str(), 0755) == 0, PETSC_COMM_SELF, PETSC_ERR_FILE_OPEN, "cannot create %s", dir.c_str());
  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  const std::string    path = dir + "/snapshots.h5";
  const SnapshotHeader h    = MakeHeader();

  // 1. Create, write 3 of 5 (not in order), close.
  {
    SnapshotFile          f;
    std::vector<PetscInt> done;
    PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true)); // restart without a file: created
    PetscCall(f.DoneIndices(&done));
    Check(done.empty() && f.IsOpen(), "restart without a file: created, nothing done");
    for (PetscInt i : {4, 0, 2}) PetscCall(f.Write(MakeSnapshot(h, i)));
    PetscCall(f.DoneIndices(&done));
    Check(done == std::vector<PetscInt>{0, 2, 4}, "after 3 writes: done = 0, 2, 4 on every rank");
    // A bad Write fails on every rank and changes nothing.
    Snapshot bad = MakeSnapshot(h, 1);
    bad.u.pop_back();
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Write(bad);
    PetscCall(PetscPopErrorHandler());
    CheckError(code, "Write with a short u", {path, "ndofs"});
    Snapshot badExtra = MakeSnapshot(h, 1);
    badExtra.extra["gap"].push_back(1.0);
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Write(badExtra);
    PetscCall(PetscPopErrorHandler());
    CheckError(code, "Write with an extra array of another length", {path, "/snapshots/extra/gap"});
    PetscCall(f.DoneIndices(&done));
    Check(done == std::vector<PetscInt>{0, 2, 4}, "failed writes leave done = 0, 2, 4");
    PetscCall(f.Close());
  }
  Check(TmpLeftovers(dir).empty(), "no *.tmp.* file left after creation");
  PetscCall(ReadAllChecked(path, h, {0, 2, 4}, "after the first run"));
  // 2. Restart: the 3 are done; write the rest (and rewrite 2 twice, ending with its original).
  {
    SnapshotFile          f;
    std::vector<PetscInt> done;
    PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true));
    PetscCall(f.DoneIndices(&done));
    Check(done == std::vector<PetscInt>{0, 2, 4}, "restart: DoneIndices == 0, 2, 4");
    for (PetscInt i : {1, 3}) PetscCall(f.Write(MakeSnapshot(h, i)));
    PetscCall(f.Write(MakeSnapshot(h, 2, 0.5)));
    PetscCall(f.Close());
    std::vector<Snapshot> snaps;
    PetscCall(SnapshotFile::ReadAll(path, &snaps));
    Check(snaps.size() == 5 && SameSnapshot(snaps[2], MakeSnapshot(h, 2, 0.5)), "rewrite of a done snapshot replaces it");
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    PetscCall(f.Open(PETSC_COMM_WORLD, path, h, true));
    PetscCall(f.Write(MakeSnapshot(h, 2)));
    PetscCall(f.DoneIndices(&done));
    Check(done == std::vector<PetscInt>{0, 1, 2, 3, 4}, "all 5 done");
    PetscCall(f.Close());
  }
  PetscCall(ReadAllChecked(path, h, {0, 1, 2, 3, 4}, "after the restart"));
  { // a version-1 file (until 2026-11-27: each snapshot's contact matrix dense in the extras contact_K and
    // contact_dofs): read with those two skipped and the other extras kept; a restart upgrades it to version 2
    // before writing; a version this build does not know is refused, naming it
    const std::string kpath = dir + "/version1.h5";
    Snapshot          s     = MakeSnapshot(h, 1);
    s.extra["contact_K"]    = std::vector<PetscReal>((size_t)h.nmult * 5, 1.5);
    s.extra["contact_dofs"] = {4, 9, 11, 20, 21};
    s.extra["contact_gap"]  = std::vector<PetscReal>(h.nmult, 0.25);
    {
      SnapshotFile f;
      PetscCall(f.Open(PETSC_COMM_WORLD, kpath, h, false));
      PetscCall(f.Write(s));
      PetscCall(f.Close());
    }
    auto setVersion = [&](int v) { // rank 0 rewrites the attribute, as a file of that version would hold it
      bool ok = true;
      if (rank == 0) {
        hid_t f = H5Fopen(kpath.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), a = f >= 0 ? H5Aopen(f, "format_version", H5P_DEFAULT) : -1;
        ok      = a >= 0 && H5Awrite(a, H5T_NATIVE_INT, &v) >= 0;
        if (a >= 0) H5Aclose(a);
        if (f >= 0) H5Fclose(f);
      }
      MPI_Barrier(PETSC_COMM_WORLD);
      return ok;
    };
    auto getVersion = [&]() {
      int v = -1;
      if (rank == 0) {
        hid_t f = H5Fopen(kpath.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), a = f >= 0 ? H5Aopen(f, "format_version", H5P_DEFAULT) : -1;
        if (a < 0 || H5Aread(a, H5T_NATIVE_INT, &v) < 0) v = -1;
        if (a >= 0) H5Aclose(a);
        if (f >= 0) H5Fclose(f);
      }
      MPI_Bcast(&v, 1, MPI_INT, 0, PETSC_COMM_WORLD);
      return v;
    };
    Check(getVersion() == 2, "a new file says format_version 2");
    Check(setVersion(1), "the file marked version 1");
    std::vector<Snapshot> snaps;
    PetscCall(SnapshotFile::ReadAll(kpath, &snaps));
    Check(snaps.size() == 1 && !snaps[0].extra.count("contact_K") && !snaps[0].extra.count("contact_dofs") && snaps[0].extra.count("contact_gap") && SameBits(snaps[0].extra["contact_gap"], s.extra["contact_gap"]) && SameBits(snaps[0].u, s.u),
          "version 1: ReadAll skips contact_K and contact_dofs, keeps the other extras and u bit for bit");
    {
      SnapshotFile          f;
      std::vector<PetscInt> done;
      PetscCall(f.Open(PETSC_COMM_WORLD, kpath, h, true));
      PetscCall(f.DoneIndices(&done));
      PetscCall(f.Close());
      Check(done == std::vector<PetscInt>{1}, "version 1: the restart sees its done snapshot");
    }
    Check(getVersion() == 2, "version 1: a restart upgrades the file to format_version 2");
    Check(setVersion(3), "the file marked version 3");
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    PetscErrorCode code = SnapshotFile::ReadAll(kpath, &snaps);
    PetscCall(PetscPopErrorHandler());
    CheckError(code, "a format_version this build does not read", {"version1.h5", "format_version 3", "versions 1 to 2"});
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  }
  {
    SnapshotHeader r;
    PetscCall(SnapshotFile::ReadHeader(path, &r));
    Check(SnapshotHeaderDiff(r, h).empty() && r.scene == h.scene && r.optionsText == h.optionsText && r.codeVersion == h.codeVersion && r.sceneHash == h.sceneHash && r.meshChecksum == h.meshChecksum, "ReadHeader == the header written (uint64 checksum > 2^63 included)");
  }
  // 3. Header mismatches refuse the restart (and leave the file alone).
  {
    SnapshotFile   f;
    SnapshotHeader other = h;
    other.meshChecksum ^= 1;
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Open(PETSC_COMM_WORLD, path, other, true);
    CheckError(code, "restart with another mesh_checksum", {path, "mesh_checksum differs", "another scene/mesh/parameter box"});
    Check(!f.IsOpen(), "refused file is not open");
    other          = h;
    other.paramMax = {2.0, 1.2};
    code           = f.Open(PETSC_COMM_WORLD, path, other, true);
    CheckError(code, "restart with another parameter box", {path, "params/max of 'load' differs (file: 1.15, now: 1.2)"});
    other                       = h;
    other.trainingPoints[3][1] += 1e-13;
    code                        = f.Open(PETSC_COMM_WORLD, path, other, true);
    CheckError(code, "restart with a training point moved by 1e-13", {path, "train/points[3][1] differs"});
    other       = h;
    other.nmult = 5;
    code        = f.Open(PETSC_COMM_WORLD, path, other, true);
    CheckError(code, "restart with another nmult", {path, "nmult"});
    PetscCall(PetscPopErrorHandler());
    other = h;
    other.trainingPoints[3][1] += 1e-15; // within 1e-14: accepted
    PetscCall(f.Open(PETSC_COMM_WORLD, path, other, true));
    PetscCall(f.Close());
    Check(true, "restart with a training point moved by 1e-15 accepted");
  }
  PetscCall(ReadAllChecked(path, h, {0, 1, 2, 3, 4}, "after the refused restarts"));
  // 4. Garbage files.
  {
    const std::string garbage = dir + "/garbage.h5", foreign = dir + "/foreign.h5";
    if (rank == 0) {
      std::ofstream(garbage) << "definitely not HDF5\n";
      hid_t f = H5Fcreate(foreign.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
      PetscCheck(f >= 0 && H5Fclose(f) >= 0, PETSC_COMM_SELF, PETSC_ERR_FILE_WRITE, "test: cannot write %s", foreign.c_str());
    }
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    SnapshotFile          f;
    std::vector<Snapshot> snaps;
    SnapshotHeader        r;
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Open(PETSC_COMM_WORLD, garbage, h, true);
    CheckError(code, "restart from a garbage file", {garbage, "not an HDF5 file"});
    code = f.Open(PETSC_COMM_WORLD, foreign, h, true);
    CheckError(code, "restart from an HDF5 file without the format attribute", {foreign, "'format'"});
    code = SnapshotFile::ReadAll(garbage, &snaps);
    CheckError(code, "ReadAll of a garbage file", {garbage, "not an HDF5 file"});
    code = SnapshotFile::ReadHeader(dir + "/missing.h5", &r);
    CheckError(code, "ReadHeader of a missing file", {dir + "/missing.h5", "does not exist"});
    code = f.Open(PETSC_COMM_WORLD, dir + "/no_such_dir/s.h5", h, false);
    CheckError(code, "create in a missing directory", {dir + "/no_such_dir/s.h5", "cannot create"});
    PetscCall(PetscPopErrorHandler());
    // Without restart an existing file (even garbage) is replaced.
    PetscCall(f.Open(PETSC_COMM_WORLD, garbage, h, false));
    std::vector<PetscInt> done;
    PetscCall(f.DoneIndices(&done));
    PetscCall(f.Close());
    PetscCall(SnapshotFile::ReadAll(garbage, &snaps));
    Check(done.empty() && snaps.empty(), "no restart: an existing (garbage) file is replaced by an empty snapshot file");
  }
  // 5. No restart on the full file: overwritten, nothing done.
  {
    SnapshotFile          f;
    std::vector<PetscInt> done;
    PetscCall(f.Open(PETSC_COMM_WORLD, path, h, false));
    PetscCall(f.DoneIndices(&done));
    PetscCall(f.Close());
    Check(done.empty(), "no restart: the existing snapshot file is overwritten");
  }
  // 5b. Declared extras (SnapshotHeader::extras) are created with the file, its rows' space taken on the disk (no hole),
  // and a Write carrying them creates nothing; a large file is created without holding it in memory (the core driver
  // extended its image to the whole file at the close: 1.4 GB of memory for a 1.4 GB file, 2026-12-04).
  {
    SnapshotHeader hx = h;
    hx.extras         = {{"gap", 3}, {"active", 2}};
    SnapshotFile f;
    PetscCall(f.Open(PETSC_COMM_WORLD, dir + "/declared.h5", hx, false));
    // the bytes stored for dataset `name` of declared.h5 (rank 0; 0 if it is not there)
    auto stored = [&](const char *name) {
      hid_t   fid = H5Fopen((dir + "/declared.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      hid_t   d   = fid >= 0 ? H5Dopen2(fid, name, H5P_DEFAULT) : -1;
      hsize_t st  = d >= 0 ? H5Dget_storage_size(d) : 0;
      if (d >= 0) H5Dclose(d);
      if (fid >= 0) H5Fclose(fid);
      return (unsigned long long)st;
    };
    if (rank == 0) { // before any Write: there, allocated
      const unsigned long long st = stored("/snapshots/extra/active");
      Check(st == 5 * 2 * 8, "declared extra /snapshots/extra/active there and allocated before the first Write (" + std::to_string(st) + " bytes, 5 x 2 doubles)");
    }
    PetscCall(f.Write(MakeSnapshot(hx, 1)));
    PetscCall(f.Close());
    std::vector<Snapshot> snaps;
    PetscCall(SnapshotFile::ReadAll(dir + "/declared.h5", &snaps));
    Check(snaps.size() == 1 && SameSnapshot(snaps[0], MakeSnapshot(hx, 1)), "declared extras: created with the file, the Write's values read back");
    if (rank == 0) Check(stored("/snapshots/extra/gap") == 5 * 3 * 8, "declared extra /snapshots/extra/gap allocated (5 x 3 doubles)");
    hx.extras = {{"a/b", 3}};
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Open(PETSC_COMM_WORLD, dir + "/badextra.h5", hx, false);
    PetscCall(PetscPopErrorHandler());
    CheckError(code, "a declared extra named a/b", {"badextra.h5", "declared extra array 'a/b'"});
    hx.extras = {{"gap", 3}, {"gap", 3}};
    PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    code = f.Open(PETSC_COMM_WORLD, dir + "/badextra.h5", hx, false);
    PetscCall(PetscPopErrorHandler());
    CheckError(code, "an extra declared twice", {"badextra.h5", "declared twice"});
    // 60 x 1e6 doubles: 480 MB of rows
    SnapshotHeader hl = h;
    hl.trainingPoints.assign(60, h.trainingPoints[0]);
    hl.ndofs  = 1000000;
    hl.extras = {{"gap", 1000}};
    struct rusage r0, r1;
    getrusage(RUSAGE_SELF, &r0);
    PetscCall(f.Open(PETSC_COMM_WORLD, dir + "/large.h5", hl, false));
    getrusage(RUSAGE_SELF, &r1);
    PetscCall(f.Close());
    if (rank == 0) {
      struct stat st;
      const bool  ok    = stat((dir + "/large.h5").c_str(), &st) == 0;
      const long  grown = r1.ru_maxrss - r0.ru_maxrss; // kB
      // (its blocks, st_blocks, are not asserted: a compressing file system stores zeros as holes)
      Check(ok && st.st_size >= 480000000, "a snapshot file of 60 x 1e6 values: " + std::to_string((long long)st.st_size) + " bytes (" + std::to_string((long long)st.st_blocks * 512) + " on the disk)");
      Check(grown < 100000, "its creation holds no copy of it in memory (peak memory grew by " + std::to_string(grown) + " kB, < 100 MB)");
    }
    std::remove((dir + "/large.h5").c_str());
  }
  // 6. A writer killed mid-run.
  PetscCall(KilledWriter(dir + "/killed.h5", h));
  // 7. Import.
  PetscCall(TestImport(dir));

  PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
  const auto left = TmpLeftovers(dir);
  Check(left.empty(), "no *.tmp.* files left in the scratch directory" + (left.empty() ? std::string() : ": " + left[0]));
  if (rank == 0) {
    if (DIR *d = opendir(dir.c_str())) {
      while (dirent *e = readdir(d))
        if (std::strcmp(e->d_name, ".") && std::strcmp(e->d_name, "..")) std::remove((dir + "/" + e->d_name).c_str());
      closedir(d);
    }
    rmdir(dir.c_str());
  }
  int total = 0;
  PetscCallMPI(MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, PETSC_COMM_WORLD));
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "test_snapshot_file: %s (%d failure%s)\n", total ? "FAILED" : "passed", total, total == 1 ? "" : "s"));
  PetscCall(PetscFinalize());
  return total ? 1 : 0;
}
