#include "scene/vtu_writer.h"

#include <fstream>
#include <iomanip>
#include <stdexcept>

namespace sedbridge::scene {
namespace {

void WriteArray(std::ofstream& out, const VtuField& f) {
  out << "        <DataArray type=\"Float64\" Name=\"" << f.name << "\" NumberOfComponents=\"" << f.components
      << "\" format=\"ascii\">\n";
  for (size_t i = 0; i < f.values.size(); ++i) out << f.values[i] << ((i + 1) % 9 == 0 ? "\n" : " ");
  out << "\n        </DataArray>\n";
}

}  // namespace

void WriteVtu(const std::string& path, const fem::TetMesh& mesh, const Eigen::VectorXd& x,
              const std::vector<VtuField>& point_fields, const std::vector<VtuField>& cell_fields) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << std::setprecision(7);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\""
      << mesh.num_nodes() << "\" NumberOfCells=\"" << mesh.num_tets() << "\">\n      <Points>\n"
      << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int i = 0; i < mesh.num_nodes(); ++i)
    out << x[3 * i] * 1e3 << " " << x[3 * i + 1] * 1e3 << " " << x[3 * i + 2] * 1e3 << "\n";
  out << "        </DataArray>\n      </Points>\n      <Cells>\n"
         "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : mesh.tets) out << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
  out << "        </DataArray>\n        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int c = 1; c <= mesh.num_tets(); ++c) out << 4 * c << ((c % 16 == 0) ? "\n" : " ");
  out << "\n        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int c = 0; c < mesh.num_tets(); ++c) out << "10" << ((c + 1) % 32 == 0 ? "\n" : " ");  // VTK_TETRA
  out << "\n        </DataArray>\n      </Cells>\n      <PointData>\n";
  VtuField displacement{"displacement_mm", 3, {}};
  for (int i = 0; i < mesh.num_nodes(); ++i)
    for (int a = 0; a < 3; ++a) displacement.values.push_back((x[3 * i + a] - mesh.rest_positions_m(a, i)) * 1e3);
  WriteArray(out, displacement);
  for (const auto& f : point_fields) WriteArray(out, f);
  out << "      </PointData>\n      <CellData>\n";
  VtuField tissue{"tissue", 1, {}};
  for (int m : mesh.tet_material) tissue.values.push_back(m);
  WriteArray(out, tissue);
  for (const auto& f : cell_fields) WriteArray(out, f);
  out << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
}

PvdCollection::PvdCollection(std::string pvd_path) : path_(std::move(pvd_path)) {}

void PvdCollection::Add(double t, const std::string& vtu_file) {
  frames_.emplace_back(t, vtu_file);
  std::ofstream out(path_);
  if (!out) throw std::runtime_error("cannot write " + path_);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [time, file] : frames_)
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  out << "  </Collection>\n</VTKFile>\n";
}

}  // namespace sedbridge::scene
