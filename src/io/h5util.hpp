// src/io/h5util.hpp: small RAII and error-context helpers over the HDF5 C API shared by the files
// rbcontact writes on rank 0 (snapshot file, ROM file): identifiers closed on scope exit, errors kept
// as one message naming the file and the dataset, whole-dataset and row I/O, attributes, flush+fsync.
// Internal (not installed): include only from src/io/*.cpp.
#pragma once
#include <hdf5.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace rbc {
namespace h5 {

// Set once HDF5 has failed on a file and the failure is in one of our messages (Ctx::Fail): HDF5 1.10.8 leaks
// free-list blocks on a failed metadata load (a checksum error) and, at MPI_Finalize, would print "HDF5: infinite
// loop closing library" and a line of interface codes below our message; it prints that only while automatic
// error printing is on (H5_term_library), so from then on H5Quiet leaves it off.
inline bool &KeepQuiet()
{
  static bool keep = false;
  return keep;
}

// Silences HDF5's automatic error-stack printing while alive (we report errors ourselves), then
// restores the previous handler (unless KeepQuiet()).
class H5Quiet {
public:
  H5Quiet()
  {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~H5Quiet()
  {
    if (!KeepQuiet()) H5Eset_auto2(H5E_DEFAULT, func_, data_);
  }
  H5Quiet(const H5Quiet &)            = delete;
  H5Quiet &operator=(const H5Quiet &) = delete;

private:
  H5E_auto2_t func_ = nullptr;
  void       *data_ = nullptr;
};

// Owns an HDF5 identifier (closed on destruction; files are closed explicitly where it matters).
class H5Id {
public:
  H5Id() = default;
  H5Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  H5Id(const H5Id &)            = delete;
  H5Id &operator=(const H5Id &) = delete;
  H5Id(H5Id &&o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  H5Id &operator=(H5Id &&o) noexcept
  {
    if (this != &o) {
      Reset();
      id_   = o.id_;
      close_ = o.close_;
      o.id_ = -1;
    }
    return *this;
  }
  ~H5Id() { Reset(); }
  void Reset()
  {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }
  hid_t Release()
  {
    hid_t id = id_;
    id_      = -1;
    return id;
  }
  bool  ok() const { return id_ >= 0; }
  hid_t get() const { return id_; }

private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// An error description of HDF5's file drivers ("file write failed: time = <date>\n, filename = ..., errno = 28, error
// message = 'No space left on device', buf = 0x..., ...", two lines and a dozen fields) cut to what it says: "file write
// failed: No space left on device (errno 28)". Other descriptions are kept as they are.
inline std::string ShortDescription(const std::string &d)
{
  const size_t t = d.find(": time = "), e = d.find("errno = "), m = d.find("error message = '");
  if (t == std::string::npos || e == std::string::npos || m == std::string::npos) return d;
  const size_t q = d.find('\'', m + 17);
  if (q == std::string::npos) return d;
  return d.substr(0, t) + ": " + d.substr(m + 17, q - m - 17) + " (errno " + std::to_string(std::atoi(d.c_str() + e + 8)) + ")";
}

inline herr_t WalkErrors(unsigned n, const H5E_error2_t *e, void *ctx)
{
  auto *v = static_cast<std::vector<std::string> *>(ctx);
  if (e && e->desc && *e->desc) v->push_back(ShortDescription(e->desc));
  return 0;
}

// The outermost and innermost descriptions of HDF5's error stack (then clears it).
inline std::string H5Detail()
{
  std::vector<std::string> d;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, WalkErrors, &d);
  H5Eclear2(H5E_DEFAULT);
  if (d.empty()) return std::string();
  return d.size() == 1 || d.front() == d.back() ? d.front() : d.front() + ": " + d.back();
}

// Error context: the first failure is kept as a message naming the file (and the dataset).
struct Ctx {
  std::string what; // "Snapshot file 'x.h5'"
  std::string err;
  bool Fail(const std::string &msg, bool hdf5 = true)
  {
    if (err.empty()) {
      err = what + ": " + msg;
      if (hdf5) {
        const std::string d = H5Detail();
        if (!d.empty()) err += " (HDF5: " + d + ")";
        KeepQuiet() = KeepQuiet() || !d.empty();
      }
    }
    return false;
  }
};

inline bool FileExists(const std::string &path)
{
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

// Whether the link `name` exists below `loc`, every group on its path checked (H5Lexists fails on a missing group).
inline bool LinkExists(Ctx &c, hid_t loc, const std::string &name, bool *exists)
{
  *exists = true;
  for (size_t k = name.find('/', 1); *exists; k = name.find('/', k + 1)) {
    const std::string prefix = name.substr(0, k);
    const htri_t      e      = H5Lexists(loc, prefix.c_str(), H5P_DEFAULT);
    if (e < 0) return c.Fail("cannot read the link " + prefix + ": a corrupt file");
    *exists = e > 0;
    if (k == std::string::npos) break;
  }
  return true;
}

// Opens dataset `name`; a failure says whether it is missing or there but unreadable (a corrupt header: with the
// checksummed metadata of MemoryFile, a damaged object header fails here, and "missing" would mislead).
inline bool OpenDataset(Ctx &c, hid_t loc, const std::string &name, H5Id *d)
{
  *d = H5Id(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (d->ok()) return true;
  const std::string detail = H5Detail();
  bool              exists = false;
  if (!LinkExists(c, loc, name, &exists)) return false;
  if (!exists) return c.Fail("missing dataset " + name, false);
  { // a group or a named datatype at that path opens as an object: not a corrupt file
    H5Id o(H5Oopen(loc, name.c_str(), H5P_DEFAULT), H5Oclose);
    const H5I_type_t t = o.ok() ? H5Iget_type(o.get()) : H5I_BADID;
    H5Eclear2(H5E_DEFAULT);
    if (t == H5I_GROUP || t == H5I_DATATYPE) return c.Fail(name + " is " + (t == H5I_GROUP ? "a group" : "a named datatype") + ", not a dataset", false);
  }
  KeepQuiet() = KeepQuiet() || !detail.empty();
  return c.Fail("dataset " + name + " is there but cannot be opened: a corrupt file" + (detail.empty() ? std::string() : " (HDF5: " + detail + ")"), false);
}

inline bool MakeStringType(Ctx &c, size_t len, H5Id *t)
{
  *t = H5Id(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!t->ok() || H5Tset_size(t->get(), len + 1) < 0 || H5Tset_strpad(t->get(), H5T_STR_NULLTERM) < 0) return c.Fail("cannot create a string type");
  return true;
}

inline bool WriteAttr(Ctx &c, hid_t obj, const char *name, hid_t ftype, hid_t mtype, const void *buf)
{
  H5Id sp(H5Screate(H5S_SCALAR), H5Sclose);
  if (!sp.ok()) return c.Fail(std::string("cannot create the dataspace of attribute '") + name + "'");
  H5Id a(H5Acreate2(obj, name, ftype, sp.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return c.Fail(std::string("cannot create attribute '") + name + "'");
  if (H5Awrite(a.get(), mtype, buf) < 0) return c.Fail(std::string("cannot write attribute '") + name + "'");
  return true;
}

inline bool WriteStringAttr(Ctx &c, hid_t obj, const char *name, const std::string &v)
{
  H5Id t;
  if (!MakeStringType(c, v.size(), &t)) return false;
  return WriteAttr(c, obj, name, t.get(), t.get(), v.c_str());
}

inline bool AttrExists(Ctx &c, hid_t obj, const char *name, bool *exists)
{
  const htri_t e = H5Aexists(obj, name);
  if (e < 0) return c.Fail(std::string("cannot query attribute '") + name + "'");
  *exists = e > 0;
  return true;
}

// A scalar integer attribute (every caller's): one stored as a float (format_version 2.7 read as 2 by HDF5's conversion)
// or holding several values (read past buf) is refused.
inline bool ReadAttr(Ctx &c, hid_t obj, const char *name, hid_t mtype, void *buf)
{
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return c.Fail(std::string("missing attribute '") + name + "'");
  {
    H5Id t(H5Aget_type(a.get()), H5Tclose), sp(H5Aget_space(a.get()), H5Sclose);
    if (!t.ok() || !sp.ok()) return c.Fail(std::string("cannot inspect attribute '") + name + "'");
    if (H5Tget_class(mtype) == H5T_INTEGER && H5Tget_class(t.get()) != H5T_INTEGER) return c.Fail(std::string("attribute '") + name + "' is not an integer (corrupt file?)", false);
    if (H5Sget_simple_extent_npoints(sp.get()) != 1) return c.Fail(std::string("attribute '") + name + "' holds " + std::to_string((long long)H5Sget_simple_extent_npoints(sp.get())) + " values, one expected (corrupt file?)", false);
  }
  if (H5Aread(a.get(), mtype, buf) < 0) return c.Fail(std::string("cannot read attribute '") + name + "'");
  return true;
}

// The size in bytes of the file holding obj (a file, dataset or attribute's object); 0 when HDF5 cannot tell.
inline hsize_t FileSizeOf(hid_t obj)
{
  hsize_t size = 0;
  H5Id    f(H5Iget_file_id(obj), H5Fclose);
  if (!f.ok() || H5Fget_filesize(f.get(), &size) < 0) size = 0;
  return size;
}

// Reads a string attribute (fixed-length or variable-length).
inline bool ReadStringAttr(Ctx &c, hid_t obj, const char *name, std::string *v)
{
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return c.Fail(std::string("missing attribute '") + name + "'");
  H5Id t(H5Aget_type(a.get()), H5Tclose);
  if (!t.ok()) return c.Fail(std::string("cannot get the type of attribute '") + name + "'");
  if (H5Tget_class(t.get()) != H5T_STRING) return c.Fail(std::string("attribute '") + name + "' is not a string", false);
  { // one string, stored in the file: an array of n was read n x its size into a buffer of one (a heap or stack overflow)
    H5Id           sp(H5Aget_space(a.get()), H5Sclose);
    const hssize_t n = sp.ok() ? H5Sget_simple_extent_npoints(sp.get()) : -1;
    if (n != 1 || H5Tget_size(t.get()) > FileSizeOf(obj))
      return c.Fail(std::string("attribute '") + name + "' is not one string stored in the file (" + std::to_string((long long)n) + " values): a corrupt file", false);
  }
  const htri_t vlen = H5Tis_variable_str(t.get());
  if (vlen < 0) return c.Fail(std::string("cannot inspect attribute '") + name + "'");
  if (vlen) {
    H5Id m(H5Tcopy(H5T_C_S1), H5Tclose);
    if (!m.ok() || H5Tset_size(m.get(), H5T_VARIABLE) < 0) return c.Fail("cannot create a string type");
    char *p = nullptr;
    if (H5Aread(a.get(), m.get(), &p) < 0) return c.Fail(std::string("cannot read attribute '") + name + "'");
    *v = p ? p : "";
    H5free_memory(p);
    return true;
  }
  const size_t size = H5Tget_size(t.get());
  if (size == 0) return c.Fail(std::string("cannot get the size of attribute '") + name + "'");
  std::vector<char> buf(size + 1, 0);
  if (H5Aread(a.get(), t.get(), buf.data()) < 0) return c.Fail(std::string("cannot read attribute '") + name + "'");
  *v = std::string(buf.data());
  return true;
}

// Creates a dataset of its final shape, contiguous, allocated now (late: at its first write); fill: the fill value
// (memory type mtype), or nullptr for no fill (the space is allocated but never initialised: sparse).
inline bool CreateDataset(Ctx &c, hid_t file, const std::string &name, hid_t ftype, const std::vector<hsize_t> &dims, hid_t mtype, const void *fill, H5Id *out, bool late = false)
{
  H5Id sp(H5Screate_simple((int)dims.size(), dims.data(), nullptr), H5Sclose);
  if (!sp.ok()) return c.Fail("cannot create the dataspace of dataset " + name);
  H5Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (!dcpl.ok() || H5Pset_layout(dcpl.get(), H5D_CONTIGUOUS) < 0 || H5Pset_alloc_time(dcpl.get(), late ? H5D_ALLOC_TIME_LATE : H5D_ALLOC_TIME_EARLY) < 0) return c.Fail("cannot set the layout of dataset " + name);
  if (fill) {
    if (H5Pset_fill_value(dcpl.get(), mtype, fill) < 0 || H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_IFSET) < 0) return c.Fail("cannot set the fill value of dataset " + name);
  } else if (H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER) < 0) return c.Fail("cannot set the fill time of dataset " + name);
  H5Id lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  if (!lcpl.ok() || H5Pset_create_intermediate_group(lcpl.get(), 1) < 0) return c.Fail("cannot create a link property list for " + name);
  H5Id d(H5Dcreate2(file, name.c_str(), ftype, sp.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT), H5Dclose);
  if (!d.ok()) return c.Fail("cannot create dataset " + name);
  if (out) *out = std::move(d);
  return true;
}

inline std::string ShapeString(const std::vector<hsize_t> &dims)
{
  std::string s;
  for (hsize_t d : dims) s += (s.empty() ? "" : " x ") + std::to_string((unsigned long long)d);
  return s.empty() ? "scalar" : s;
}

inline bool DatasetDims(Ctx &c, hid_t d, const std::string &name, std::vector<hsize_t> *dims)
{
  H5Id sp(H5Dget_space(d), H5Sclose);
  if (!sp.ok()) return c.Fail("cannot get the dataspace of dataset " + name);
  const int rank = H5Sget_simple_extent_ndims(sp.get());
  if (rank < 0) return c.Fail("cannot get the rank of dataset " + name);
  dims->assign((size_t)rank, 0);
  if (rank > 0 && H5Sget_simple_extent_dims(sp.get(), dims->data(), nullptr) < 0) return c.Fail("cannot get the shape of dataset " + name);
  // A corrupted dataspace declares more values than the file stores: refused here, before a reader allocates them (a
  // fuzzed ROM file of 115 kB declared 4294966024 values: 4.2 GB allocated and zeroed, then H5Dread failed). Checked
  // for contiguous datasets (every one CreateDataset makes, h5py's default), whose storage is all there once written;
  // an unwritten one (no storage) passes if it fits in the file. A chunked dataset (h5py with compression or maxshape;
  // rbcontact writes none) must hold every chunk its shape needs: an unwritten chunk reads as the fill value, so a
  // declared shape of 2^32 rows over one stored chunk was a ROM file of 157 kB that asked for 447 GB (refused since
  // 2026-12-03; compression itself is fine: the chunks are counted, not their bytes).
  H5Id t(H5Dget_type(d), H5Tclose);
  H5Id pl(H5Dget_create_plist(d), H5Pclose);
  const H5D_layout_t layout = pl.ok() ? H5Pget_layout(pl.get()) : H5D_LAYOUT_ERROR;
  // A virtual dataset reads other files (or, unmapped, its fill value for any declared shape) and external storage
  // reads raw files beside it: neither is what rbcontact or h5py writes by default, and neither can be checked here.
  if (layout == H5D_VIRTUAL) return c.Fail("dataset " + name + " is a virtual dataset (its values live in other files): rbcontact reads datasets stored in the file itself; copy it into a plain dataset", false);
  if (pl.ok() && H5Pget_external_count(pl.get()) > 0) return c.Fail("dataset " + name + " has external storage (its values live in raw files beside it): rbcontact reads datasets stored in the file itself; copy it into a plain dataset", false);
  if (layout == H5D_CHUNKED && rank > 0) {
    std::vector<hsize_t> chunk((size_t)rank, 0);
    hsize_t              stored = 0;
    if (H5Pget_chunk(pl.get(), rank, chunk.data()) != rank || H5Dget_num_chunks(d, sp.get(), &stored) < 0) return c.Fail("cannot get the chunks of dataset " + name);
    long double need = 1;
    for (int i = 0; i < rank; ++i) need *= chunk[i] > 0 ? std::ceil((long double)(*dims)[i] / (long double)chunk[i]) : 0.0L;
    if ((long double)stored < need) {
      std::ostringstream m;
      m << "dataset " << name << " declares shape " << ShapeString(*dims) << " in chunks of " << ShapeString(chunk) << " but stores " << (unsigned long long)stored << " of its " << (unsigned long long)std::min(need, 1.8e19L) << " chunks: a corrupt or truncated file";
      return c.Fail(m.str(), false);
    }
  }
  if (t.ok() && layout == H5D_CONTIGUOUS) {
    long double bytes = (long double)H5Tget_size(t.get());
    for (hsize_t x : *dims) bytes *= (long double)x;
    const hsize_t stored = H5Dget_storage_size(d);
    const hsize_t fsize  = FileSizeOf(d);
    if (bytes > (long double)stored && (stored > 0 || bytes > (long double)fsize)) {
      std::ostringstream m;
      m << "dataset " << name << " declares shape " << ShapeString(*dims) << " (" << (double)bytes << " bytes), more than the file stores for it (" << (unsigned long long)stored << " bytes; the file has " << (unsigned long long)fsize << "): a corrupt or truncated file";
      return c.Fail(m.str(), false);
    }
  }
  return true;
}

// Dataset `name` has shape `expect` (checked by DatasetDims against what the file stores).
inline bool HasShape(Ctx &c, hid_t file, const std::string &name, const std::vector<hsize_t> &expect)
{
  H5Id d;
  std::vector<hsize_t> dims;
  if (!OpenDataset(c, file, name, &d) || !DatasetDims(c, d.get(), name, &dims)) return false;
  if (dims != expect) return c.Fail("dataset " + name + " has shape " + ShapeString(dims) + ", expected " + ShapeString(expect) + " (corrupt file?)", false);
  return true;
}

// Whole-dataset write / read with a shape check.
inline bool WriteWhole(Ctx &c, hid_t file, const std::string &name, hid_t ftype, const std::vector<hsize_t> &dims, hid_t mtype, const void *buf)
{
  H5Id d;
  if (!CreateDataset(c, file, name, ftype, dims, mtype, nullptr, &d)) return false;
  hsize_t n = 1;
  for (hsize_t x : dims) n *= x;
  if (n > 0 && H5Dwrite(d.get(), mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) return c.Fail("cannot write dataset " + name);
  return true;
}

inline bool ReadWhole(Ctx &c, hid_t file, const std::string &name, const std::vector<hsize_t> &expect, std::vector<double> *v)
{
  if (!HasShape(c, file, name, expect)) return false;
  H5Id d;
  if (!OpenDataset(c, file, name, &d)) return false;
  hsize_t n = 1;
  for (hsize_t x : expect) n *= x;
  v->assign(n, 0.0);
  if (n > 0 && H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->data()) < 0) return c.Fail("cannot read dataset " + name);
  return true;
}

// Reads or writes row `row` (ncols values) of a 1D (ncols = 1) or 2D dataset.
inline bool RowIO(Ctx &c, hid_t file, const std::string &name, hid_t mtype, hsize_t row, hsize_t ncols, void *buf, bool write)
{
  H5Id d;
  if (!OpenDataset(c, file, name, &d)) return false;
  H5Id fs(H5Dget_space(d.get()), H5Sclose);
  if (!fs.ok()) return c.Fail("cannot get the dataspace of dataset " + name);
  const int rank = H5Sget_simple_extent_ndims(fs.get());
  hsize_t   dims[2] = {0, 0};
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(fs.get(), dims, nullptr) < 0) return c.Fail("dataset " + name + " is not 1D or 2D");
  const hsize_t cols = rank == 1 ? 1 : dims[1];
  if (cols != ncols || row >= dims[0]) {
    std::ostringstream m;
    m << "dataset " << name << " has shape " << ShapeString(std::vector<hsize_t>(dims, dims + rank)) << "; cannot " << (write ? "write" : "read") << " row " << row << " of length " << ncols;
    return c.Fail(m.str(), false);
  }
  if (ncols == 0) return true;
  const hsize_t start[2] = {row, 0}, count[2] = {1, ncols};
  if (H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0) return c.Fail("cannot select row of dataset " + name);
  H5Id ms(H5Screate_simple(1, &ncols, nullptr), H5Sclose);
  if (!ms.ok()) return c.Fail("cannot create a memory dataspace for " + name);
  const herr_t st = write ? H5Dwrite(d.get(), mtype, ms.get(), fs.get(), H5P_DEFAULT, buf) : H5Dread(d.get(), mtype, ms.get(), fs.get(), H5P_DEFAULT, buf);
  if (st < 0) return c.Fail(std::string("cannot ") + (write ? "write" : "read") + " row " + std::to_string((unsigned long long)row) + " of dataset " + name);
  return true;
}

// A file rbcontact writes whole (ROM, basis files, a new snapshot file), built in memory by HDF5 (the core driver, no
// backing store) in the 1.8 file format (H5Pset_libver_bounds V18..V18): superblock v2, object headers v2, whose
// metadata (headers, attributes, dataspaces, links) HDF5 checksums, so a corrupted header is an error on opening
// rather than a wrong shape, a crash or a wrong value (docs/bad_input.md). Not the 1.10 format: its superblock v3 marks
// a file open for writing, and a snapshot file left by a killed job would need h5clear (docs/snapshot_file.md).
// Readable by HDF5 >= 1.8 (h5py, ParaView). Files opened for writing later keep the format they have.
// In memory because HDF5 (1.10.8) cannot close a file on disk whose metadata it failed to write (a full disk): the
// identifier stayed, and HDF5's shutdown at MPI_Finalize crashed on it (a segmentation fault after our message;
// docs/bad_input.md "A full disk"). Save closes the file, which hands HDF5's final image to this object (the file
// image callbacks: no copy), and writes it with write(2) + fsync, so the disk's errors are ours, with their errno.
// Declare it before the H5Id of its file (the close hands the image over; the destructor frees it).
class MemoryFile {
public:
  MemoryFile() = default;
  MemoryFile(const MemoryFile &)            = delete;
  MemoryFile &operator=(const MemoryFile &) = delete;
  ~MemoryFile() { std::free(image_); }

  // The file, H5I_INVALID_HID on a failure whose reason stays on HDF5's error stack. (HDF5 first tries to open `name`:
  // a stale file there, e.g. a temporary file of a killed job with the same pid, is read into memory and dropped, and
  // Save's O_TRUNC replaces it.)
  hid_t Create(const std::string &name)
  {
    hid_t f = H5I_INVALID_HID, why = H5I_INVALID_HID;
    {
      H5FD_file_image_callbacks_t cb = {Malloc, Memcpy, Realloc, Free, UdataCopy, UdataFree, this};
      H5Id                        fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
      // (a strong close: H5Fclose closes every object of the file and the driver, so the image is handed over at that
      // call, never later into a destroyed MemoryFile)
      if (!fapl.ok() || H5Pset_fapl_core(fapl.get(), (size_t)1 << 20, 0) < 0 || H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18) < 0 ||
          H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0 || H5Pset_file_image_callbacks(fapl.get(), &cb) < 0)
        return H5I_INVALID_HID;
      f = H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
      if (f < 0) why = H5Eget_current_stack(); // the H5Pclose of fapl, a successful call, would clear the stack that says why
    }
    if (why >= 0) H5Eset_current_stack(why); // (and closes the copy): the caller's Ctx::Fail reads it
    return f;
  }

  // Closes *file and writes its image to path (created or truncated), then `reserve` more bytes of zeros after its
  // end (the room the file will take when its late-allocated datasets are allocated: the disk's blocks taken now), then
  // fsync.
  bool Save(Ctx &c, H5Id *file, const std::string &path, unsigned long long reserve = 0)
  {
    const hid_t id = file->Release();
    if (H5Fclose(id) < 0 || !image_) return c.Fail("cannot close the file's image in memory");
    // the file's length is the end of file its superblock records: the driver's memory (in steps of 1 MB) may end
    // before it (space allocated and never written: a snapshot file's rows), which is written as zeros
    const unsigned char *u  = static_cast<const unsigned char *>(image_);
    const size_t         so = size_ >= 12 ? u[9] : 0;
    unsigned long long   eof = 0;
    if (size_ < 12 + 3 * so || std::memcmp(u, "\211HDF\r\n\032\n", 8) != 0 || (u[8] != 2 && u[8] != 3) || so < 4 || so > 8)
      return c.Fail("the file's image does not start with a version-2 superblock", false);
    for (size_t k = 0; k < so; ++k) eof |= (unsigned long long)u[12 + 2 * so + k] << (8 * k);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return c.Fail(std::string("cannot create the file: ") + std::strerror(errno), false);
    // (zeros written, not a hole: the space is the disk's now, so a full disk is said here, not at a later row)
    const unsigned long long         end = eof + reserve;
    const unsigned long long         inMem = std::min<unsigned long long>(eof, size_);
    const std::vector<unsigned char> zeros(end > inMem ? std::min<unsigned long long>(end - inMem, 1 << 20) : 0, 0);
    int                              err = 0;
    unsigned long long               off = 0;
    while (off < end) {
      const bool    mem = off < size_ && off < eof;
      const size_t  len = mem ? (size_t)(std::min<unsigned long long>(eof, size_) - off) : (size_t)std::min<unsigned long long>(end - off, zeros.size());
      const ssize_t w   = ::write(fd, mem ? u + off : zeros.data(), len);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        err = w < 0 ? errno : EIO;
        break;
      }
      off += (unsigned long long)w;
    }
    if (!err && ::fsync(fd) != 0) err = errno;
    if (::close(fd) != 0 && !err) err = errno;
    if (err) return c.Fail("cannot write the file (" + std::to_string(end) + " bytes): " + std::strerror(err), false);
    return true;
  }

private:
  // (the size of the driver's buffer: its allocations for the file, not the copies of property lists)
  static void Track(void *q, size_t n, H5FD_file_image_op_t op, void *self)
  {
    if (q && (op == H5FD_FILE_IMAGE_OP_FILE_OPEN || op == H5FD_FILE_IMAGE_OP_FILE_RESIZE)) static_cast<MemoryFile *>(self)->size_ = n;
  }
  static void *Malloc(size_t n, H5FD_file_image_op_t op, void *self)
  {
    void *q = std::malloc(n);
    Track(q, n, op, self);
    return q;
  }
  static void *Memcpy(void *d, const void *s, size_t n, H5FD_file_image_op_t, void *) { return std::memcpy(d, s, n); }
  static void *Realloc(void *p, size_t n, H5FD_file_image_op_t op, void *self)
  {
    void *q = std::realloc(p, n);
    Track(q, n, op, self);
    return q;
  }
  static herr_t Free(void *p, H5FD_file_image_op_t op, void *self)
  {
    auto *m = static_cast<MemoryFile *>(self);
    if (op == H5FD_FILE_IMAGE_OP_FILE_CLOSE && p) { // the file's final image: kept for Save
      std::free(m->image_);
      m->image_ = p;
    } else std::free(p);
    return 0;
  }
  static void  *UdataCopy(void *self) { return self; } // (the property lists share this object)
  static herr_t UdataFree(void *) { return 0; }

  void  *image_ = nullptr;
  size_t size_  = 0;
};

// H5Fflush, then fsync of the file descriptor (data reaches the disk, not only the OS cache).
inline bool FlushSync(Ctx &c, hid_t file)
{
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) return c.Fail("H5Fflush failed");
  void *handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || !handle) return c.Fail("cannot get the file descriptor");
  if (fsync(*static_cast<int *>(handle)) != 0) return c.Fail(std::string("fsync failed: ") + std::strerror(errno), false);
  return true;
}


} // namespace h5
} // namespace rbc
