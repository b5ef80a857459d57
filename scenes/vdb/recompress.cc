// Rewrites a .vdb file's grids with another compression, using the real OpenVDB library (C++: the
// Python module does not expose the file's compression). Built and run by make_fixtures.py:
//   recompress IN.vdb OUT.vdb zip|none
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <cstring>
#include <iostream>

int main(int argc, char** argv) {
    if (argc != 4) {
        std::cerr << "usage: recompress IN.vdb OUT.vdb zip|none\n";
        return 2;
    }
    openvdb::initialize();
    openvdb::io::File in(argv[1]);
    in.open();
    openvdb::GridPtrVecPtr grids = in.getGrids();
    openvdb::MetaMap::Ptr meta = in.getMetadata();
    in.close();
    openvdb::io::File out(argv[2]);
    if (std::strcmp(argv[3], "zip") == 0) {
        out.setCompression(openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
    } else {
        out.setCompression(openvdb::io::COMPRESS_NONE);
    }
    out.write(*grids, *meta);
    out.close();
    return 0;
}
