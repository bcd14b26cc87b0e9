#!/usr/bin/env python3
"""The packed Ptex tables of docs/PTEX.md from bench trade rows (JSON lines): per model, RGBA8
PSNR of mesh colors / MCT / Ptex per view, frame ratios, GPU bytes, Ptex texel overheads,
build times, and the largest seam jump per level."""
import json, sys, math, collections
for path in sys.argv[1:]:
    rows=[json.loads(l) for l in open(path)]
    meta=[r for r in rows if r.get('kind')=='meta'][0]
    print(f"## {path}: {meta['triangles']} triangles, reps {meta['representations']}")
    cfg=[r for r in rows if r.get('kind')=='config' and r['format']=='rgba8']
    res=sorted({json.dumps(r['resolution']) for r in cfg if isinstance(r['resolution'], int)}, key=lambda s:int(s))
    def get(rep, R, filt, view):
        for r in cfg:
            if r['representation']==rep and json.dumps(r['resolution'])==R and r['filter']==filt and r['view']==view:
                return r
    print("| R | PSNR near lin MC/MCT/Ptex | PSNR mid lin | PSNR far tri | PSNR tiny tri | frame tri mid MC/MCT/Ptex (×UV) | GPU bytes MC/MCT/Ptex | Ptex/MC bytes | Ptex border/interior, unused/interior | build ms MCT/Ptex |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for R in res:
        def ps(filt, view):
            vals=[]
            for rep in ['mesh-colors','mct','ptex']:
                r=get(rep,R,filt,view)
                vals.append('–' if r is None or r.get('psnr_db') is None else '%.1f'%r['psnr_db'])
            return ' / '.join(vals)
        fr=[]
        for rep in ['mesh-colors','mct','ptex']:
            r=get(rep,R,'trilinear','mid'); fr.append('–' if r is None else '%.2f'%r['frame_ratio'])
        b=[]
        for rep in ['mesh-colors','mct','ptex']:
            r=get(rep,R,'linear','mid'); b.append('–' if r is None else '%d k'%(r['gpu_bytes']//1000))
        p=get('ptex',R,'linear','mid'); m=get('mct',R,'linear','mid')
        print(f"| {R} | {ps('linear','near')} | {ps('linear','mid')} | {ps('trilinear','far')} | {ps('trilinear','tiny')} | {' / '.join(fr)} | {' / '.join(b)} | {p['ptex_bytes_over_mesh_colors']:.2f} | {p['ptex_border_over_interior']*100:.1f} %, {p['ptex_unused_over_interior']*100:.1f} % | {m['mct_build_seconds']*1e3:.1f} / {p['ptex_build_seconds']*1e3:.1f} |")
    seams=[r for r in rows if r.get('kind')=='seam' and r['format'] in ('rgba8','rgba32f')]
    print()
    print("| R | seam max, linear, level 0 / 1 / 2 / 3: mesh colors (rgba32f) ; MCT (rgba8) ; Ptex (rgba8) |")
    print("|---|---|")
    for R in res:
        out=[]
        for rep,fmt in [('mesh-colors','rgba32f'),('mct','rgba8'),('ptex','rgba8')]:
            v=[]
            for lvl in range(4):
                s=[r for r in seams if r['representation']==rep and r['format']==fmt and json.dumps(r['resolution'])==R and r['filter']=='linear' and r['level']==lvl]
                v.append('%.3f'%s[0]['max_jump'] if s else '–')
            out.append(' / '.join(v))
        print(f"| {R} | {' ; '.join(out)} |")
    print()
