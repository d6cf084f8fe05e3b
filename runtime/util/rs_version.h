/* The program's version, in util so that every layer (the command line's
 * `ringside version`, the service's GET /health) may print it. */
#ifndef RS_VERSION_H
#define RS_VERSION_H

#define RS_VERSION "0.1.0"

#endif
