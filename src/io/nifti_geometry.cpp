// NIfTI geometry as nibabel (and FSL, SPM) read it, replacing what ITK's NiftiImageIO reports:
// the sform when its code is set (ITK prefers the qform), else the qform, with pixdim taken as
// |pixdim| and an invalid qfac as 1 (nibabel's header fixes); xyzt_units applied to spacing and
// origin alike; a 2D image keeps the affine's third column and z offset. World coordinates
// are LPS (the NIfTI RAS affine with x and y negated), like every other reader here.
#include <zlib.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "io/io_internal.h"

namespace vs::io_detail {

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

template <class T>
T field(const unsigned char* h, int off, bool swap) {
  T v;
  std::memcpy(&v, h + off, sizeof v);
  if (swap) byteSwap(&v, sizeof v, 1);
  return v;
}

struct Affines {
  int qcode = 0, scode = 0;
  Eigen::Matrix<double, 3, 4> q, s;  // RAS, file units
  int units = 0;                     // xyzt_units & 7
  bool twoD = false;
};

bool readAffines(const std::string& path, Affines& a) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return false;
  unsigned char h[540];
  const int n = gzread(f, h, sizeof h);
  gzclose(f);
  if (n < 348) return false;
  int32_t size;
  std::memcpy(&size, h, 4);
  const bool swap = !(size == 348 || size == 540);
  if (swap) byteSwap(&size, 4, 1);
  double pix[4], quat[3], qoff[3], srow[12];
  int64_t ndim;
  if (size == 348) {
    ndim = field<int16_t>(h, 40, swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<float>(h, 76 + 4 * i, swap);
    a.units = h[123] & 7;
    a.qcode = field<int16_t>(h, 252, swap);
    a.scode = field<int16_t>(h, 254, swap);
    for (int i = 0; i < 3; ++i) quat[i] = field<float>(h, 256 + 4 * i, swap);
    for (int i = 0; i < 3; ++i) qoff[i] = field<float>(h, 268 + 4 * i, swap);
    for (int i = 0; i < 12; ++i) srow[i] = field<float>(h, 280 + 4 * i, swap);
    // Analyze 7.5 (no NIfTI magic) has no qform/sform.
    if (std::memcmp(h + 344, "n+1", 4) != 0 && std::memcmp(h + 344, "ni1", 4) != 0) a.qcode = a.scode = 0;
  } else if (size == 540 && n >= 540) {
    ndim = field<int64_t>(h, 16, swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<double>(h, 104 + 8 * i, swap);
    a.qcode = field<int32_t>(h, 344, swap);
    a.scode = field<int32_t>(h, 348, swap);
    for (int i = 0; i < 3; ++i) quat[i] = field<double>(h, 352 + 8 * i, swap);
    for (int i = 0; i < 3; ++i) qoff[i] = field<double>(h, 376 + 8 * i, swap);
    for (int i = 0; i < 12; ++i) srow[i] = field<double>(h, 400 + 8 * i, swap);
    a.units = field<int32_t>(h, 500, swap) & 7;
  } else {
    return false;
  }
  a.twoD = ndim == 2;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.s(r, c) = srow[4 * r + c];
  // qform (nifti1_io / nibabel): rotation from the quaternion, |pixdim|, qfac = pixdim[0] or 1.
  double b = quat[0], c = quat[1], d = quat[2];
  double w = 1.0 - (b * b + c * c + d * d);
  double aq;
  if (w < 1e-7) {  // nibabel: a = 0 and (b, c, d) normalised
    const double norm = std::sqrt(b * b + c * c + d * d);
    if (norm > 0) b /= norm, c /= norm, d /= norm;
    aq = 0;
  } else {
    aq = std::sqrt(w);
  }
  Mat3 R;
  R << aq * aq + b * b - c * c - d * d, 2 * (b * c - aq * d), 2 * (b * d + aq * c), 2 * (b * c + aq * d),
      aq * aq + c * c - b * b - d * d, 2 * (c * d - aq * b), 2 * (b * d - aq * c), 2 * (c * d + aq * b),
      aq * aq + d * d - c * c - b * b;
  const double qfac = pix[0] == -1 ? -1 : 1;
  Vec3 vox(std::fabs(pix[1]), std::fabs(pix[2]), std::fabs(pix[3]) * qfac);
  for (int i = 0; i < 3; ++i)
    if (vox[i] == 0) vox[i] = i == 2 ? qfac : 1;
  a.q.leftCols<3>() = R * vox.asDiagonal();
  a.q.col(3) = Vec3(qoff[0], qoff[1], qoff[2]);
  return true;
}

double maxCos(const Mat3& d) {
  return std::max(
      {std::fabs(d.col(0).dot(d.col(1))), std::fabs(d.col(0).dot(d.col(2))), std::fabs(d.col(1).dot(d.col(2)))});
}

}  // namespace

void applyNiftiGeometry(const std::string& path, Geometry& g, ReadInfo& info) {
  Affines a;
  if (!readAffines(path, a)) return;
  const bool useS = a.scode > 0, useQ = !useS && a.qcode > 0;
  if (!useS && !useQ) return;  // no orientation: ITK's pixdim-only geometry stays
  Eigen::Matrix<double, 3, 4> A = useS ? a.s : a.q;
  if (!A.allFinite()) return;  // checked before ITK already; keep ITK's reading
  const double unit = a.units == 1 ? 1000.0 : a.units == 3 ? 0.001 : 1.0;
  if (unit != 1.0)
    info.notes.push_back(std::string("NIfTI xyzt_units ") + (a.units == 1 ? "metre" : "micron") +
                         ": spacing and origin converted to mm");
  A *= unit;
  A.row(0) *= -1;  // RAS -> LPS
  A.row(1) *= -1;
  Mat3 M = A.leftCols<3>();
  Vec3 sp(M.col(0).norm(), M.col(1).norm(), M.col(2).norm());
  if (sp.minCoeff() <= 0 || !sp.allFinite()) {
    info.notes.push_back(std::string("NIfTI ") + (useS ? "sform" : "qform") +
                         " has a zero column: the pixdim geometry was used");
    return;
  }
  Mat3 D = M * sp.cwiseInverse().asDiagonal();
  const double c = maxCos(D);
  if (c > 1e-6) {
    if (c > 0.02 && useS && a.qcode > 0) {
      info.notes.push_back("NIfTI sform is sheared (axes " + num(std::asin(c) * 180 / M_PI) +
                           " degrees from orthogonal), which a voxel grid cannot hold: the qform was used");
      A = a.q * unit;
      A.row(0) *= -1;
      A.row(1) *= -1;
      M = A.leftCols<3>();
      sp = Vec3(M.col(0).norm(), M.col(1).norm(), M.col(2).norm());
      D = M * sp.cwiseInverse().asDiagonal();
    } else if (c > 0.02) {
      throw IoError(path + ": NIfTI " + (useS ? "sform" : "qform") + " is sheared (axes " +
                    num(std::asin(c) * 180 / M_PI) + " degrees from orthogonal) and there is no qform to fall back on");
    }
    // Nearest orthonormal frame (polar decomposition): float32 rounding of a rotation.
    Eigen::JacobiSVD<Mat3> svd(D, Eigen::ComputeFullU | Eigen::ComputeFullV);
    D = svd.matrixU() * svd.matrixV().transpose();
    if (c > 1e-4)
      info.notes.push_back("NIfTI " + std::string(useS ? "sform" : "qform") + " axes were " + num(c) +
                           " (cosine) from orthogonal: orthonormalised");
  }
  if (useS && a.qcode > 0) {
    const Eigen::Matrix<double, 3, 4> dq = a.q - a.s;
    if (dq.cwiseAbs().maxCoeff() > 1e-3)
      info.notes.push_back("NIfTI sform and qform differ (up to " + num(dq.cwiseAbs().maxCoeff()) +
                           " mm): the sform was used, as nibabel, FSL and SPM do");
  }
  g.spacing = sp;
  g.direction = D;
  g.origin = A.col(3);
}

}  // namespace vs::io_detail

namespace vs::io_detail {

AnyVolume readNiftiVoxels(const std::string& path, double slope, double inter, ReadInfo& info) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw IoError(path + ": cannot open for reading");
  unsigned char h[540];
  const int n = gzread(f, h, sizeof h);
  gzclose(f);
  if (n < 348) throw IoError(path + ": truncated NIfTI header");
  int32_t size;
  std::memcpy(&size, h, 4);
  const bool swap = !(size == 348 || size == 540);
  if (swap) byteSwap(&size, 4, 1);
  int64_t dim[8] = {0};
  double pix[4];
  int dt;
  double voxOffset;
  if (size == 348) {
    for (int i = 0; i < 8; ++i) dim[i] = field<int16_t>(h, 40 + 2 * i, swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<float>(h, 76 + 4 * i, swap);
    dt = field<int16_t>(h, 70, swap);
    voxOffset = field<float>(h, 108, swap);
  } else {
    if (n < 540) throw IoError(path + ": truncated NIfTI-2 header");
    for (int i = 0; i < 8; ++i) dim[i] = field<int64_t>(h, 16 + 8 * i, swap);
    for (int i = 0; i < 4; ++i) pix[i] = field<double>(h, 104 + 8 * i, swap);
    dt = field<int16_t>(h, 12, swap);
    voxOffset = static_cast<double>(field<int64_t>(h, 168, swap));
  }
  Comp c;
  switch (dt) {
    case 2:
      c = Comp::UInt8;
      break;
    case 4:
      c = Comp::Int16;
      break;
    case 8:
      c = Comp::Int32;
      break;
    case 16:
      c = Comp::Float32;
      break;
    case 64:
      c = Comp::Float64;
      break;
    case 256:
      c = Comp::Int8;
      break;
    case 512:
      c = Comp::UInt16;
      break;
    case 768:
      c = Comp::UInt32;
      break;
    case 1024:
      c = Comp::Int64;
      break;
    case 1280:
      c = Comp::UInt64;
      break;
    default:
      throw IoError(path + ": unsupported NIfTI datatype " + std::to_string(dt));
  }
  Geometry g;
  for (int i = 0; i < 3; ++i) {
    g.dims[i] = i < dim[0] ? std::max<int64_t>(dim[i + 1], 1) : 1;
    g.spacing[i] = std::fabs(pix[i + 1]) > 0 ? std::fabs(pix[i + 1]) : 1.0;
  }
  checkAllocation(g.dims, compSize(c), path);
  std::string where = path, ext = path.size() > 4 ? path.substr(path.size() - 4) : path;
  if (ext == ".hdr") where = path.substr(0, path.size() - 4) + ".img";
  gzFile d = gzopen(where.c_str(), "rb");
  if (!d) throw IoError(where + ": cannot open the NIfTI image data");
  const size_t bytes = static_cast<size_t>(g.voxelCount()) * compSize(c);
  std::vector<char> buf(bytes);
  const bool ok = gzseek(d, static_cast<z_off_t>(ext == ".hdr" ? 0 : voxOffset), SEEK_SET) >= 0 &&
                  gzread(d, buf.data(), static_cast<unsigned>(bytes)) == static_cast<int>(bytes);
  gzclose(d);
  if (!ok) throw IoError(path + ": truncated NIfTI data");
  if (swap) byteSwap(buf.data(), compSize(c), static_cast<size_t>(g.voxelCount()));
  AnyVolume vol = convertBuffer(buf.data(), c, 1, g, info, path);
  if (std::isfinite(slope) && slope != 0 && (slope != 1 || inter != 0)) {
    VolumeF32 out(g);
    std::visit(
        [&](const auto& v) {
          for (int64_t i = 0; i < v.size(); ++i)
            out.data()[i] = static_cast<float>(static_cast<double>(v.data()[i]) * slope + inter);
        },
        vol);
    vol = std::move(out);
  }
  return vol;
}

}  // namespace vs::io_detail
