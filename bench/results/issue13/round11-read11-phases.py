import sys, subprocess, re, collections
groups = [
 ('face table', r'getme__ws_faces'),
 ('workspace (boundary search)', r'number_nodes|radix_sort|order_elements|build_stars|getme__ws_build|colour_blocks|getme__ws_'),
 ('fix boundary', r'fix_boundary|read_fixed|topology|skin'),
 ('validity check', r'element_qualities|getme__quality|block_stats|check_valid'),
 ('model build', r'model_number|repeated_node|add_elements|nodemap|add_run|getme_mesh_create|set_fixed_mask|model_finish|relabel'),
 ('parse ASCII ints', r'fast_u64|msh41_digits|element_line|tag_line'),
 ('parse ASCII reals', r'numparse|coord_line|strtod|fast_double'),
 ('store elements', r'store_element|store_records'),
 ('reader other', r'msh41|linepar|memmove|memcpy|memrchr|memset'),
 ('kernel: file read copy', r'^\[k\] (_copy_to_iter|copy_page_to_iter|filemap_|rep_movs|copy_user)'),
 ('kernel: faults, other', r'^\[k\]'),
]
def parse(path):
    out = subprocess.run(['perf','report','-i',path,'--no-children','--sort','sym','--stdio','-F','sample,sym','-g','none'],capture_output=True,text=True).stdout
    tot = collections.Counter(); allc=0
    for line in out.splitlines():
        m = re.match(r'\s*(\d+)\s+(\[.\])\s+(.*)', line)
        if not m: continue
        n=int(m.group(1)); sym=m.group(2)+' '+m.group(3).strip(); allc+=n
        for g,rx in groups:
            if re.search(rx, sym if g.startswith('kernel') else m.group(3)):
                tot[g]+=n; break
        else: tot['other']+=n
    tot['TOTAL']=allc
    return tot
res = [parse(p) for p in sys.argv[1:]]
names=[g for g,_ in groups]+['other','TOTAL']
print('phase | ' + ' | '.join(a.split('/')[-1] for a in sys.argv[1:]))
for g in names: print(g+' | '+' | '.join(str(r[g]) for r in res))
