#include "scene/vtu_writer.h"

#include <cctype>
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

// A name safe inside a VTK array name: letters, digits and '_' only.
std::string ArrayNamePart(const std::string& s) {
  std::string r;
  for (char c : s) r += (std::isalnum(static_cast<unsigned char>(c)) ? c : '_');
  return r.empty() ? "unnamed" : r;
}

}  // namespace

void WriteVtu(const std::string& path, const fem::TetMesh& mesh, const Eigen::VectorXd& x,
              const std::vector<VtuField>& point_fields, const std::vector<VtuField>& cell_fields,
              const std::vector<std::pair<std::string, double>>& field_values) {
  for (const auto& f : point_fields)
    if (f.name == "displacement_mm") throw std::invalid_argument("WriteVtu writes displacement_mm itself");
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << std::setprecision(7);
  out << "<?xml version=\"1.0\"?>\n"
         "<!-- sedbridge: points are the reference (undeformed) positions [mm]; displacement_mm is\n"
         "     deformed - reference [mm]: Warp By Vector with it (scale 1) shows the deformed shape.\n"
         "     Cell array tissue: code per tet, named by the FieldData arrays tissue_<code>_<name>. -->\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <UnstructuredGrid>\n    <FieldData>\n";
  // Tissue names as FieldData: one Int32 array per tissue, named after it, holding its code.
  for (size_t m = 0; m < mesh.materials.size(); ++m)
    out << "      <DataArray type=\"Int32\" Name=\"tissue_" << m << "_" << ArrayNamePart(mesh.materials[m].name)
        << "\" NumberOfTuples=\"1\" format=\"ascii\">" << m << "</DataArray>\n";
  for (const auto& [name, value] : field_values)
    out << "      <DataArray type=\"Float64\" Name=\"" << ArrayNamePart(name)
        << "\" NumberOfTuples=\"1\" format=\"ascii\">" << value << "</DataArray>\n";
  out << "    </FieldData>\n    <Piece NumberOfPoints=\"" << mesh.num_nodes() << "\" NumberOfCells=\""
      << mesh.num_tets() << "\">\n      <Points>\n"
      << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int i = 0; i < mesh.num_nodes(); ++i)
    out << mesh.rest_positions_m(0, i) * 1e3 << " " << mesh.rest_positions_m(1, i) * 1e3 << " "
        << mesh.rest_positions_m(2, i) * 1e3 << "\n";
  out << "        </DataArray>\n      </Points>\n      <Cells>\n"
         "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : mesh.tets) out << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
  out << "        </DataArray>\n        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int c = 1; c <= mesh.num_tets(); ++c) out << 4 * c << ((c % 16 == 0) ? "\n" : " ");
  out << "\n        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int c = 0; c < mesh.num_tets(); ++c) out << "10" << ((c + 1) % 32 == 0 ? "\n" : " ");  // VTK_TETRA
  // Vectors=: ParaView's Warp By Vector picks displacement_mm without being told.
  out << "\n        </DataArray>\n      </Cells>\n      <PointData Vectors=\"displacement_mm\">\n";
  VtuField displacement{"displacement_mm", 3, {}};
  displacement.values.reserve(size_t(3 * mesh.num_nodes()));
  for (int i = 0; i < mesh.num_nodes(); ++i)
    for (int a = 0; a < 3; ++a) displacement.values.push_back((x[3 * i + a] - mesh.rest_positions_m(a, i)) * 1e3);
  WriteArray(out, displacement);
  for (const auto& f : point_fields) WriteArray(out, f);
  out << "      </PointData>\n      <CellData Scalars=\"tissue\">\n";
  VtuField tissue{"tissue", 1, {}};
  for (int m : mesh.tet_material) tissue.values.push_back(m);
  WriteArray(out, tissue);
  for (const auto& f : cell_fields) WriteArray(out, f);
  out << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
}

PvdCollection::PvdCollection(std::string pvd_path, std::string time_meaning)
    : path_(std::move(pvd_path)), time_meaning_(std::move(time_meaning)) {}

void PvdCollection::Add(double time, const std::string& vtu_file) {
  frames_.emplace_back(time, vtu_file);
  std::ofstream out(path_);
  if (!out) throw std::runtime_error("cannot write " + path_);
  out << "<?xml version=\"1.0\"?>\n<!-- sedbridge: timestep = " << time_meaning_
      << " -->\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [t, file] : frames_)
    out << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  out << "  </Collection>\n</VTKFile>\n";
}

}  // namespace sedbridge::scene
