// OpenImageIO behind a C interface (see cap_oiio.h).  Kept to what capture
// needs: a reference resize, image files for sequences, and float images
// for image-based lighting (runtime/render/r_ibl.c).
#include "cap_oiio.h"

#include <cstdio>
#include <cstdlib>
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

extern "C" bool cap_oiio_read_float(const char *path, int *w, int *h, float **rgb, char *err, size_t errn)
{
    *rgb = nullptr;
    auto in = ImageInput::open(path);
    if (!in)
        return fail(err, errn, path, "cannot read image: " + OIIO::geterror());
    const ImageSpec &spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
        return fail(err, errn, path, "not a 2-D image (" + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) +
                                         " channels)");
    if (spec.width > CAP_OIIO_MAX_SIDE || spec.height > CAP_OIIO_MAX_SIDE)
        return fail(err, errn, path, std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                         " is larger than " + std::to_string(CAP_OIIO_MAX_SIDE) + "x" +
                                         std::to_string(CAP_OIIO_MAX_SIDE));
    size_t npix = (size_t)spec.width * (size_t)spec.height;
    float *p = (float *)std::malloc(npix * 3 * sizeof(float));
    if (!p)
        return fail(err, errn, path, "out of memory for " + std::to_string(spec.width) + "x" +
                                         std::to_string(spec.height) + " RGB floats");
    int nch = spec.nchannels >= 3 ? 3 : 1;
    /* x stride of three floats: a grey image lands in the first of each triple */
    if (!in->read_image(0, 0, 0, nch, TypeDesc::FLOAT, p, 3 * sizeof(float))) {
        std::string e = in->geterror();
        std::free(p);
        return fail(err, errn, path, e.empty() ? "read failed" : e);
    }
    if (nch == 1)
        for (size_t k = 0; k < npix; k++)
            p[3 * k + 1] = p[3 * k + 2] = p[3 * k];
    in->close();
    *w = spec.width;
    *h = spec.height;
    *rgb = p;
    return true;
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
extern "C" bool cap_oiio_read_float(const char *path, int *, int *, float **rgb, char *err, size_t errn)
{
    *rgb = nullptr;
    std::snprintf(err, errn, "%s: built without OpenImageIO, so no image environments (install "
                             "libopenimageio-dev and rebuild)", path);
    return false;
}
extern "C" const char *cap_oiio_version(void)
{
    return "no OpenImageIO in this build";
}
#endif
