/* The announcer's clips (the WAVs of runtime/audio/voice/, rendered by
 * tools/gen-voice.sh), embedded byte for byte so the binary needs no data
 * files at run time.  Each clip is au_vd_NAME .. au_vd_NAME_end; the list
 * of names is the one in au_voice.c.  The paths are relative to the source
 * tree, which the Makefile gives the assembler (-Wa,-I). */
    .macro clip name
    .globl au_vd_\name, au_vd_\name\()_end
    .balign 4
au_vd_\name:
    .incbin "runtime/audio/voice/\name\().wav"
au_vd_\name\()_end:
    .endm

    .section .rodata
    clip round1
    clip round2
    clip round3
    clip round4
    clip round5
    clip fight
    clip ko
    clip ring_out
    clip time
    clip draw
    clip p1_wins
    clip p2_wins

/* no executable stack for the program that links this */
    .section .note.GNU-stack, "", @progbits
