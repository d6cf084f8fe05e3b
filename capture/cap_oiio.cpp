// OpenImageIO behind a C interface (see cap_oiio.h).  Kept to what capture
// needs: a reference resize and image files for sequences.
#include "cap_oiio.h"

#include <cstdio>
#include <cstring>

#ifdef RS_HAVE_OIIO
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

using namespace OIIO;

static bool fail(char *err, size_t n, const char *what, const std::string &why)
{
    std::snprintf(err, n, "%s: %s", what, why.c_str());
    for (char *p = err; *p; p++)
        if (*p == '\n')
            *p = ' ';
    return false;
}

extern "C" bool cap_oiio_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, char *err, size_t errn)
{
    ImageSpec in_spec(sw, sh, 4, TypeDesc::UINT8);
    ImageBuf src(in_spec, const_cast<uint8_t *>(rgba));
    ImageSpec out_spec(w, h, 4, TypeDesc::FLOAT);
    ImageBuf dst(out_spec);
    if (!ImageBufAlgo::resize(dst, src))
        return fail(err, errn, "OpenImageIO resize", dst.geterror());
    if (!dst.get_pixels(ROI(0, w, 0, h, 0, 1, 0, 4), TypeDesc::FLOAT, out))
        return fail(err, errn, "OpenImageIO resize", dst.geterror());
    for (size_t i = 0; i < (size_t)w * h * 4; i++)
        out[i] *= 255.0f;
    return true;
}

extern "C" bool cap_oiio_write(const char *path, const char *ext, int w, int h, const uint8_t *rgba, char *err,
                               size_t errn)
{
    auto o = ImageOutput::create(ext + 1); /* by format name: path may end in .part */
    if (!o)
        return fail(err, errn, path, "OpenImageIO cannot write " + std::string(ext) + ": " + OIIO::geterror());
    ImageSpec spec(w, h, 4, TypeDesc::UINT8);
    if (!std::strcmp(ext, ".exr"))
        spec.set_format(TypeDesc::HALF);
    spec.alpha_channel = 3;
    if (!o->open(path, spec))
        return fail(err, errn, path, o->geterror());
    bool ok = o->write_image(TypeDesc::UINT8, rgba);
    std::string e = ok ? "" : o->geterror();
    if (!o->close() && ok) {
        ok = false;
        e = o->geterror();
    }
    return ok ? true : fail(err, errn, path, e.empty() ? "write failed" : e);
}

extern "C" const char *cap_oiio_version(void)
{
    static char v[64];
    std::snprintf(v, sizeof v, "OpenImageIO %s", OIIO_VERSION_STRING);
    return v;
}

#else
extern "C" bool cap_oiio_resize(const uint8_t *, int, int, float *, int, int, char *err, size_t errn)
{
    std::snprintf(err, errn, "this build has no OpenImageIO (install libopenimageio-dev and rebuild)");
    return false;
}
extern "C" bool cap_oiio_write(const char *path, const char *, int, int, const uint8_t *, char *err, size_t errn)
{
    std::snprintf(err, errn, "%s: this build has no OpenImageIO, so no image sequences", path);
    return false;
}
extern "C" const char *cap_oiio_version(void)
{
    return "no OpenImageIO in this build";
}
#endif
